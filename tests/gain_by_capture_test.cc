// Where a fit's gain comes from (calib/gain_by_capture.h): the capture
// whose sum of squares fell most, and its share of the whole fall.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "calib/gain_by_capture.h"
#include "calib/least_squares.h"

namespace hj {
namespace {

namespace fs = std::filesystem;

const fs::path kBaseline = fs::path(HJ_SHARED_DIR) / "data/sessions/demo-baseline";

TEST(GainByCapture, FindsTheCaptureThatCarriesTheFallAndItsShare) {
  const Dataset d = select_sessions(read_dataset(kBaseline), {"unjammed-sweep", "mixed-1"}, true);
  const std::vector<long> rows = capture_rows(d);
  ASSERT_GE(rows.size(), 4u);
  const Eigen::VectorXd before = Eigen::VectorXd::Constant(rows.back(), 1.0);
  Eigen::VectorXd after = before;
  // The second capture of the dataset halves its residuals; the third
  // lowers them a little.
  after.segment(rows[1], rows[2] - rows[1]).setConstant(0.5);
  after.segment(rows[2], rows[3] - rows[2]).setConstant(0.9);
  const CaptureGain gain = largest_capture_gain(d, before, after);
  EXPECT_EQ(gain.session, 0);
  EXPECT_EQ(gain.capture, 1);
  EXPECT_DOUBLE_EQ(gain.before_rmse_mm, 1.0);
  EXPECT_DOUBLE_EQ(gain.after_rmse_mm, 0.5);
  const double fall1 = 0.75 * (rows[2] - rows[1]), fall2 = 0.19 * (rows[3] - rows[2]);
  EXPECT_NEAR(gain.share, fall1 / (fall1 + fall2), 1e-12);
  EXPECT_NE(capture_name(d, 0, 1).find(d.sessions[0].captures[1].frame), std::string::npos);
}

TEST(GainByCapture, NoFallHasNoCaptureAndNoShare) {
  const Dataset d = select_sessions(read_dataset(kBaseline), {"unjammed-sweep"}, true);
  const Eigen::VectorXd r = Eigen::VectorXd::Constant(capture_rows(d).back(), 1.0);
  const CaptureGain gain = largest_capture_gain(d, r, 1.1 * r);
  EXPECT_EQ(gain.capture, -1);
  EXPECT_TRUE(std::isnan(gain.share));
}

TEST(GainByCapture, ResidualsOfAnotherDatasetAreRejectedNamingTheCounts) {
  const Dataset d = select_sessions(read_dataset(kBaseline), {"unjammed-sweep"}, true);
  const long n = capture_rows(d).back();
  try {
    largest_capture_gain(d, Eigen::VectorXd::Zero(n), Eigen::VectorXd::Zero(n + 1));
    FAIL() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(std::to_string(n + 1)), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace hj
