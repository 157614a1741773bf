// The scan for a candidate effect's start (calib/effect_scan.h), on one
// cheap session of the shared datasets at their true baseline: where the
// data have the bare membrane's bending stiffness (demo-bending, kappa0 =
// 0.002 N m/rad) the scan moves kappa_bend from 0 to within a half decade
// of it; where they have none (demo-baseline) it keeps the start.
#include <gtest/gtest.h>

#include <filesystem>

#include "calib/effect_scan.h"

namespace hj {
namespace {

namespace fs = std::filesystem;

const fs::path kSessions = fs::path(HJ_SHARED_DIR) / "data/sessions";

ModelParams true_baseline() {
  ModelParams m;
  m.surface.mass_kg = 0.52;
  m.surface.spring_k = 58.0;
  m.surface.kappa_jam = 4.2;
  return with_effects(m, {"bending"});
}

double kappa_bend(const ModelParams& p) { return p.effect_parameters.at("bending").at("kappa_bend"); }

TEST(EffectScan, MovesTheBendingStiffnessTowardWhatTheDataHave) {
  const Dataset d = select_sessions(read_dataset(kSessions / "demo-bending"), {"mixed-2"}, true);
  const ModelParams start = true_baseline();
  ASSERT_EQ(kappa_bend(start), 0.0);
  ReplayOptions replay = fitting_replay({});  // as diagnose scans
  replay.threads = 1;
  const EffectScan scan = scan_effect_start(d, start, fit_parameters({"bending"}), "bending", replay);
  EXPECT_TRUE(scan.moved) << scan.note;
  EXPECT_GT(kappa_bend(scan.best), 0.002 / 3.2);
  EXPECT_LT(kappa_bend(scan.best), 0.002 * 3.2);
  EXPECT_LT(scan.best_sum_sq_mm2, 0.5 * scan.start_sum_sq_mm2);
  EXPECT_NE(scan.note.find("bending.kappa_bend 0 -> "), std::string::npos) << scan.note;
  // One direction (kappa_bend >= 0), stopped after two rises: fewer than
  // the start and the whole ladder of seven points.
  EXPECT_LT(scan.replays, 8);
}

TEST(EffectScan, KeepsTheStartWhereTheDataHaveNoBending) {
  const Dataset d = select_sessions(read_dataset(kSessions / "demo-baseline"), {"mixed-1"}, true);
  ReplayOptions replay = fitting_replay({});  // as diagnose scans
  replay.threads = 1;
  const EffectScan scan = scan_effect_start(d, true_baseline(), fit_parameters({"bending"}), "bending", replay);
  EXPECT_FALSE(scan.moved) << scan.note;
  EXPECT_EQ(kappa_bend(scan.best), 0.0);
  EXPECT_EQ(scan.best_sum_sq_mm2, scan.start_sum_sq_mm2);
  EXPECT_TRUE(scan.note.empty());
}

}  // namespace
}  // namespace hj
