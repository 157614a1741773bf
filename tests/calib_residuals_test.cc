// Residuals of model versus measurement (calib/residuals.h) and datasets
// (calib/dataset.h): known errors on hand-made frames, the device state of
// each capture in the shared dataset, and errors that name what is wrong.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>

#include "calib/dataset.h"
#include "calib/levelling.h"
#include "calib/residuals.h"
#include "expect_error.h"
#include "scratch_dir.h"

namespace hj {
namespace {

namespace fs = std::filesystem;
using testing_support::expect_error;
using testing_support::ScratchDir;

const fs::path kBaseline = fs::path(HJ_SHARED_DIR) / "data/sessions/demo-baseline";
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

TEST(CompareCapture, KnownErrorsSkipMissingAndUncoveredSamples) {
  Eigen::MatrixXd measured(2, 3), predicted(2, 3);
  measured << 0.0, 1.0, kNaN, 2.0, 2.0, 5.0;
  predicted << 3.0, 1.0, 9.0, 2.0, -2.0, kNaN;
  const CaptureError e = compare_capture(predicted, measured, 3.0);
  // Compared: residuals 3, 0, 0, -4; the NaN frame sample and the uncovered one do not count.
  EXPECT_EQ(e.samples, 4);
  EXPECT_EQ(e.uncovered, 1);
  EXPECT_DOUBLE_EQ(e.rmse_mm(), std::sqrt(25.0 / 4.0));
  EXPECT_DOUBLE_EQ(e.mae_mm(), 7.0 / 4.0);
  EXPECT_DOUBLE_EQ(e.max_mm, 4.0);
  EXPECT_DOUBLE_EQ(e.mean_mm, -1.0 / 4.0);
  EXPECT_DOUBLE_EQ(e.share_within_accuracy(), 3.0 / 4.0);
  EXPECT_TRUE(std::isnan(e.residual_mm(0, 2)));
  EXPECT_DOUBLE_EQ(e.residual_mm(1, 1), -4.0);
}

TEST(CompareCapture, ShapeMismatchIsAnError) {
  expect_error<std::invalid_argument>(
      [] { compare_capture(Eigen::MatrixXd::Zero(2, 3), Eigen::MatrixXd::Zero(3, 2), 1.0); }, {"shape"});
}

TEST(Dataset, CapturesKnowTheDeviceStateTheyWereTakenIn) {
  const Dataset d = read_dataset(kBaseline);
  ASSERT_EQ(d.sessions.size(), 6u);
  EXPECT_EQ(d.capture_count(), 38);
  const Dataset jammed = select_sessions(d, {"jammed-sweep"}, true);
  ASSERT_EQ(jammed.sessions.size(), 1u);
  const auto& captures = jammed.sessions[0].captures;
  ASSERT_EQ(captures.size(), 10u);
  EXPECT_EQ(captures[0].jammed_count(), 0);  // rest
  EXPECT_EQ(captures[1].jammed_count(), 12);  // all jammed, at 0 kPa
  EXPECT_DOUBLE_EQ(captures[1].pressure_pa, 0.0);
  EXPECT_NEAR(captures.back().pressure_pa, 3450.0, 1e-6);
  const Dataset paper = select_sessions(d, {"paper-sequence"}, true);
  EXPECT_EQ(paper.sessions[0].captures[1].pinned.size(), 4u);
  EXPECT_EQ(select_sessions(d, {"jammed-sweep"}, false).sessions.size(), 5u);
}

TEST(Dataset, CellOfSampleFollowsTheFootprints) {
  const Dataset d = select_sessions(read_dataset(kBaseline), {"mixed-1"}, true);
  const Session& s = d.sessions[0].session;  // 2 mm grid from 0, 38 mm cells
  int r = -1, c = -1;
  ASSERT_TRUE(cell_of_sample(s, 0, 0, r, c));
  EXPECT_EQ(r, 0);
  EXPECT_EQ(c, 0);
  ASSERT_TRUE(cell_of_sample(s, 19, 18, r, c));  // x 38 mm (on the border), y 36 mm
  EXPECT_EQ(c, 1);
  EXPECT_EQ(r, 0);
  ASSERT_TRUE(cell_of_sample(s, 76, 57, r, c));  // the far corner
  EXPECT_EQ(c, 3);
  EXPECT_EQ(r, 2);
}

TEST(Dataset, BadFoldersAndNamesAreNamed) {
  ScratchDir dir;
  expect_error<SessionError>([&] { read_dataset(dir.path); }, {dir.path.string(), "no session folders"});
  expect_error<SessionError>([&] { read_dataset(dir.path / "missing"); }, {"not a dataset folder"});
  const Dataset d = read_dataset(kBaseline);
  expect_error<SessionError>([&] { select_sessions(d, {"nope"}, true); }, {"nope", "mixed-1"});
}

TEST(Levelling, ZeroCrossingGivesTheStatedMass) {
  // demo-baseline: M = 0.52 kg, so the levelling pressure is 294.4 Pa.
  const LevellingEstimate e = levelling_mass(read_dataset(kBaseline), 9.81);
  ASSERT_TRUE(e.found);
  EXPECT_EQ(e.session, "unjammed-sweep");
  EXPECT_LT(e.below_pa, e.pressure_pa);
  EXPECT_GT(e.above_pa, e.pressure_pa);
  EXPECT_NEAR(e.mass_kg, 0.52, 0.1 * 0.52);
}

}  // namespace
}  // namespace hj
