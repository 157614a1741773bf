// The scan for a candidate effect's start (calib/effect_scan.h), on one
// cheap session of the shared datasets at their true baseline: where the
// data have the bare membrane's bending stiffness (demo-bending, kappa0 =
// 0.002 N m/rad) the scan moves kappa_bend from 0 to within a half decade
// of it; where they have none (demo-baseline) it keeps the start.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "calib/effect_scan.h"
#include "calib/measurement_effects.h"

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

// Fitted without a stiff jammed cell (kappa_jam 0.11, spring_k 41) the
// membrane creases at the clamped corners near 2 kPa, and any bending
// there leaves it without an equilibrium. From that replaying start, a
// point with no equilibrium counts as a rise: two end the direction.
TEST(EffectScan, EndsADirectionAfterTwoPointsWithNoEquilibriumFromAStartThatReplays) {
  const Dataset d = select_sessions(read_dataset(kSessions / "demo-baseline"), {"mixed-3"}, true);
  ModelParams start = true_baseline();
  start.surface.spring_k = 41.4;
  start.surface.kappa_jam = 0.114;
  ReplayOptions replay = fitting_replay({});
  replay.threads = 1;
  const EffectScan scan = scan_effect_start(d, start, fit_parameters({"bending"}), "bending", replay);
  ASSERT_TRUE(std::isfinite(scan.start_sum_sq_mm2)) << "the start must replay, or this test shows nothing";
  EXPECT_FALSE(scan.moved) << scan.note;
  EXPECT_EQ(scan.failed, 2);
  EXPECT_EQ(scan.replays, 3);  // the start and two points
}

// area_pressure's default (weight 1) has no equilibrium at 2 kPa: from
// that start, points with none are stepped over until one replays.
TEST(EffectScan, StepsOverPointsWithNoEquilibriumFromAStartThatDoesNotReplay) {
  const Dataset d = select_sessions(read_dataset(kSessions / "demo-baseline"), {"mixed-3"}, true);
  ModelParams start = with_effects(true_baseline(), {"area_pressure"});
  ReplayOptions replay = fitting_replay({});
  replay.threads = 1;
  const EffectScan scan =
      scan_effect_start(d, start, fit_parameters({"area_pressure"}), "area_pressure", replay);
  ASSERT_FALSE(std::isfinite(scan.start_sum_sq_mm2)) << "the start must fail, or this test shows nothing";
  EXPECT_TRUE(scan.moved) << scan.note;
  EXPECT_GT(scan.failed, 2);
  EXPECT_NE(scan.note.find("the start does not replay"), std::string::npos) << scan.note;
}

// A camera tilt changes no surface: its scan replays the dataset once per
// replay setting, not once per point, and finds the very same figures.
TEST(EffectScan, ScansAMeasurementEffectOnOneReplayWithTheSameFigures) {
  const Dataset d = select_sessions(read_dataset(kSessions / "demo-bending"), {"mixed-2"}, true);
  ModelParams start = with_effects(true_baseline(), {"sensor_tilt"});
  start.effects = {"sensor_tilt"};  // the data's bending left out: the offset soaks up some of it
  start.effect_parameters.erase("bending");
  ReplayOptions replay = fitting_replay({});
  replay.threads = 1;
  const auto parameters = fit_parameters({"sensor_tilt"});
  EffectScanOptions every_point;
  every_point.reuse_measurement_replays = false;
  const EffectScan replayed = scan_effect_start(d, start, parameters, "sensor_tilt", replay, every_point);
  const EffectScan reused = scan_effect_start(d, start, parameters, "sensor_tilt", replay);
  ASSERT_TRUE(replayed.moved) << "the scan should move something here, or this test shows nothing";
  EXPECT_EQ(reused.moved, replayed.moved);
  EXPECT_EQ(reused.note, replayed.note);
  EXPECT_EQ(reused.start_sum_sq_mm2, replayed.start_sum_sq_mm2);
  EXPECT_EQ(reused.best_sum_sq_mm2, replayed.best_sum_sq_mm2);
  EXPECT_EQ(model_params_json(reused.best), model_params_json(replayed.best));
  EXPECT_EQ(reused.failed, replayed.failed);
  EXPECT_LE(reused.replays, 2);  // the start's replay settings and the points'
  EXPECT_GT(replayed.replays, 6);
}

TEST(CameraFreeReplay, GivesTheReplayedSumOfSquaresAtAnyTiltAndRefusesOtherSurfaces) {
  const Dataset d = select_sessions(read_dataset(kSessions / "demo-bending"), {"mixed-2"}, true);
  ModelParams tilted = with_effects(true_baseline(), {"sensor_tilt"});
  tilted.effect_parameters["sensor_tilt"] = {{"tilt_x_mrad", 3.0}, {"tilt_y_mrad", -7.0}, {"offset_mm", 0.4}};
  ReplayOptions replay = fitting_replay({});
  replay.threads = 1;
  EXPECT_TRUE(is_measurement_only("sensor_tilt"));
  EXPECT_FALSE(is_measurement_only("bending"));
  EXPECT_FALSE(is_measurement_only("pressure_offset"));  // it changes the pressure the surface feels
  const CameraFreeReplay surfaces(d, with_effects(true_baseline(), {"sensor_tilt"}), replay);
  ASSERT_TRUE(surfaces.replayed());
  EXPECT_EQ(surfaces.sum_of_squares(tilted), dataset_sum_of_squares(d, tilted, replay));
  ModelParams level = tilted;
  level.effect_parameters["sensor_tilt"] = {{"tilt_x_mrad", 0.0}, {"tilt_y_mrad", 0.0}, {"offset_mm", 0.0}};
  EXPECT_EQ(surfaces.sum_of_squares(level), dataset_sum_of_squares(d, level, replay));
  EXPECT_NE(surfaces.sum_of_squares(level), surfaces.sum_of_squares(tilted));
  ModelParams stiffer = tilted;
  stiffer.surface.spring_k *= 1.01;
  EXPECT_THROW(surfaces.sum_of_squares(stiffer), std::invalid_argument);
}

}  // namespace
}  // namespace hj
