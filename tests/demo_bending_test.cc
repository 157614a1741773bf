// Acceptance of the bending effect against the shared dataset demo-bending
// (its README: the baseline truth M 0.52 kg, k 58 N/m, kappa_jam 4.2 N m/rad,
// plus bare-membrane bending kappa0 = 0.002 N m/rad at every interior and
// border point): with `bending` at the stated stiffness every capture is
// reproduced to within the camera noise, and without it the unjammed sweep
// is not.
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

const fs::path kBending = fs::path(HJ_SHARED_DIR) / "data/sessions/demo-bending";

using testing_support::demo_true_parameters;

SimulatorOptions with_bending(double kappa_bend) {
  SimulatorOptions o;
  o.extra_effects = {"bending"};
  o.effect_parameters["bending"] = {{"kappa_bend", kappa_bend}};
  return o;
}

// Largest mean absolute difference (mm) over the session's captures.
double worst_capture_mad(const std::string& name, const SimulatorOptions& options) {
  const Session session = read_session(kBending / name);
  const auto predicted = replay_session(session, 4, demo_true_parameters(), options);
  double worst = 0.0;
  for (const PredictedCapture& capture : predicted) {
    const Eigen::MatrixXd real = read_frame_csv(session.dir / capture.frame, session.grid.ny, session.grid.nx);
    const CaptureError error = compare_capture(capture.heights_mm, real, 1.0);
    EXPECT_GT(error.samples, 0.95 * real.size()) << name << "/" << capture.frame;
    worst = std::max(worst, error.mae_mm());
  }
  std::cout << "  " << name << ": worst capture mean |diff| " << worst << " mm\n";
  return worst;
}

TEST(DemoBending, ReproducedWithTheStatedBendingStiffness) {
  for (const char* name : {"unjammed-sweep", "jammed-sweep", "paper-sequence", "mixed-1", "mixed-2", "mixed-3"}) {
    SCOPED_TRACE(name);
    EXPECT_LE(worst_capture_mad(name, with_bending(0.002)), 1.2) << "mean absolute difference, mm";
  }
}

TEST(DemoBending, BaselineMissesTheUnjammedSweep) {
  EXPECT_GT(worst_capture_mad("unjammed-sweep", SimulatorOptions{}), 1.5) << "mean absolute difference, mm";
}

}  // namespace
}  // namespace hj
