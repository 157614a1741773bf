// Acceptance: the baseline model with the true parameters of the synthetic
// dataset demo-baseline (M 0.52 kg, k 58 N/m, kappa_jam 4.2 N m/rad, p = 4)
// reproduces every capture of its six sessions to within the camera noise
// (sigma 1 mm, rounded to 1 mm: a perfect model leaves a mean absolute
// difference of about 0.8 mm).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <iostream>
#include <string>

#include "calib/frame_csv.h"
#include "calib/replay.h"
#include "calib/residuals.h"
#include "calib/session.h"
#include "demo_truth.h"

namespace hj {
namespace {

namespace fs = std::filesystem;

const fs::path kBaseline = fs::path(HJ_SHARED_DIR) / "data/sessions/demo-baseline";

using testing_support::demo_true_parameters;

void expect_session_reproduced(const std::string& name, int expected_captures) {
  const Session session = read_session(kBaseline / name);
  const auto predicted = replay_session(session, 4, demo_true_parameters(), SimulatorOptions{});
  ASSERT_EQ(static_cast<int>(predicted.size()), expected_captures);
  for (const PredictedCapture& capture : predicted) {
    SCOPED_TRACE(name + "/" + capture.frame);
    const Eigen::MatrixXd real = read_frame_csv(session.dir / capture.frame, session.grid.ny, session.grid.nx);
    ASSERT_EQ(capture.heights_mm.rows(), real.rows());
    ASSERT_EQ(capture.heights_mm.cols(), real.cols());
    const CaptureError error = compare_capture(capture.heights_mm, real, 1.0);
    const int count = error.samples;
    // About 1 % of the samples are dropped; the rest must be compared.
    EXPECT_GT(count, 0.95 * real.size());
    const double mad = error.mae_mm();
    std::cout << "  " << name << "/" << capture.frame << " (" << capture.label << "): mean |diff| " << mad
              << " mm over " << count << " samples\n";
    EXPECT_LE(mad, 1.2) << "mean absolute difference, mm";
  }
}

TEST(DemoBaseline, UnjammedSweep) { expect_session_reproduced("unjammed-sweep", 11); }
TEST(DemoBaseline, JammedSweep) { expect_session_reproduced("jammed-sweep", 10); }
TEST(DemoBaseline, PaperSequence) { expect_session_reproduced("paper-sequence", 4); }
TEST(DemoBaseline, Mixed1) { expect_session_reproduced("mixed-1", 4); }
TEST(DemoBaseline, Mixed2) { expect_session_reproduced("mixed-2", 4); }
TEST(DemoBaseline, Mixed3) { expect_session_reproduced("mixed-3", 5); }

}  // namespace
}  // namespace hj
