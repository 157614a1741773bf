// A dataset whose effect no candidate can represent is not explained away:
// the final model's residuals are tested against the sensor's noise model
// (calib/goodness_of_fit.h), the verdict says the model does not explain
// the data and where the residual concentrates.
#include <gtest/gtest.h>

#include <cmath>

#include "calib/diagnosis.h"
#include "calib/frame_csv.h"
#include "calib/goodness_of_fit.h"
#include "calib/report/diagnose_report_html.h"
#include "calib_synthetic.h"
#include "scratch_dir.h"

namespace hj {
namespace {

namespace fs = std::filesystem;

// The effect written only for this test: a fixed bump the camera sees over
// cell (1, 2) (a smudge on its window, an object on the membrane), 5 mm
// high and 8 mm wide, whatever the surface does. No registry effect has
// this form. Added to every frame, rounded to the camera's 1 mm.
void add_camera_bump(const fs::path& data) {
  const double cx = 2.5 * 38.0, cy = 1.5 * 38.0, height = 5.0, sigma = 8.0;
  for (const auto& entry : fs::recursive_directory_iterator(data)) {
    if (entry.path().extension() != ".csv") continue;
    Eigen::MatrixXd h = read_frame_csv(entry.path(), 58, 77);
    for (int iy = 0; iy < h.rows(); ++iy)
      for (int ix = 0; ix < h.cols(); ++ix) {
        const double r2 = std::pow(2.0 * ix - cx, 2) + std::pow(2.0 * iy - cy, 2);
        h(iy, ix) += std::round(height * std::exp(-r2 / (2 * sigma * sigma)));
      }
    write_frame_csv(entry.path(), h);
  }
}

// The tiny sessions replayed with the true baseline, the bump added.
Dataset bump_dataset(const fs::path& dir) {
  testing_support::write_tiny_sessions(dir / "sessions");
  synthesize_dataset(dir / "sessions", dir / "data", testing_support::true_tiny_baseline(), SynthOptions{});
  add_camera_bump(dir / "data");
  return read_dataset(dir / "data");
}

TEST(GoodnessOfFit, ChiSquareTailMatchesKnownQuantiles) {
  // chi2_{1000}: the 95th percentile is 1074.68, the median 999.33.
  EXPECT_NEAR(chi_square_upper_tail(1074.68, 1000), 0.05, 1e-3);
  EXPECT_NEAR(chi_square_upper_tail(999.33, 1000), 0.5, 2e-3);
  EXPECT_LT(chi_square_upper_tail(1300, 1000), 1e-9);
  LeastSquaresResult fit;
  fit.residual_count = 100000;
  fit.free_parameters = 3;
  fit.rmse_mm = 1.0;
  fit.sum_sq_mm2 = 1e5;
  EXPECT_TRUE(goodness_of_fit(fit, 1.0).explained);
  fit.rmse_mm = 1.5;
  fit.sum_sq_mm2 = 2.25e5;
  const GoodnessOfFit bad = goodness_of_fit(fit, 1.0);
  EXPECT_FALSE(bad.explained);
  EXPECT_LT(bad.p_value, 1e-9);
  EXPECT_NEAR(bad.systematic_mm, std::sqrt(1.25), 1e-12);
}

TEST(CalibDiagnoseUnexplained, AnEffectNoCandidateHasIsNotExplainedAway) {
  testing_support::ScratchDir scratch("bump");
  const Dataset d = bump_dataset(scratch.path);
  DiagnoseOptions o;
  o.candidates = {"sensor_tilt", "pressure_offset", "cell_stiffness"};
  o.max_effects = 1;
  o.fit.least_squares.max_iterations = 10;
  const Diagnosis result = diagnose(d, ModelParams{}, o);
  EXPECT_FALSE(result.goodness.explained);
  EXPECT_GT(result.goodness.rmse_mm, 1.1 * result.noise_floor_mm);
  EXPECT_LT(result.goodness.p_value, 1e-6);
  ASSERT_FALSE(result.final_pattern.worst_cells.empty());
  EXPECT_EQ(result.final_pattern.worst_cells[0], std::make_pair(1, 2));
  const std::string verdict = verdict_sentence(result);
  EXPECT_NE(verdict.find("does not explain the data"), std::string::npos) << verdict;
  EXPECT_NE(verdict.find("[1, 2]"), std::string::npos) << verdict;
  EXPECT_EQ(verdict.find("No effect is needed"), std::string::npos) << verdict;
}

// Where a candidate's local refit leaves the data unexplained, its new
// parameter is searched over its whole range (calib/multi_start.h) before
// it is judged; the search does not explain the bump away either.
TEST(CalibDiagnoseUnexplained, AnUnexplainedRefitIsSearchedOverItsParametersRange) {
  testing_support::ScratchDir scratch("bump-range");
  const Dataset d = bump_dataset(scratch.path);
  DiagnoseOptions o;
  o.candidates = {"stiffening"};
  o.max_effects = 1;
  o.screening = false;  // refit it whatever the screening predicts
  o.fit.least_squares.max_iterations = 10;
  const Diagnosis result = diagnose(d, ModelParams{}, o);
  ASSERT_EQ(result.ranking.size(), 1u);
  const CandidateFit& stiffening = result.ranking.front();
  EXPECT_EQ(stiffening.multi_start_parameter, "stiffening.beta");
  EXPECT_EQ(stiffening.starts_tried.size(), 4u);
  EXPECT_FALSE(result.goodness.explained) << fit_quality_sentence(result);
}

}  // namespace
}  // namespace hj
