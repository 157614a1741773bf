// An effect far stronger than the synthetic matrix's is found as reliably
// as a small one: a strain stiffening with beta near its upper range
// (tension several times the linear spring's at the sweep's largest
// stretches), which the baseline absorbs into a stiffer k, is diagnosed as
// stiffening with diagnose's defaults. Its local refit explains the data,
// so the search over beta's range (calib/multi_start.h), which runs where a
// local refit leaves the data unexplained, is not paid for here.
#include <gtest/gtest.h>

#include "calib/diagnosis.h"
#include "calib/multi_start.h"
#include "calib/report/diagnose_report_html.h"
#include "calib_synthetic.h"
#include "scratch_dir.h"

namespace hj {
namespace {

constexpr double kBeta = 600.0;

TEST(MultiStart, StartsSpanTheRange) {
  EXPECT_EQ(range_starts({"beta", "1", 0.0, 0.0, 1000.0}, 4), (std::vector<double>{1.0, 10.0, 100.0, 1000.0}));
  const auto factor = range_starts({"factor", "1", 1.0, 0.2, 5.0}, 3);
  ASSERT_EQ(factor.size(), 3u);
  EXPECT_NEAR(factor[1], 1.0, 1e-12);
  EXPECT_EQ(range_starts({"gain", "1", 0.0, -0.3, 0.3}, 3), (std::vector<double>{-0.3, 0.0, 0.3}));
}

// An effect of several parameters has each started over its range in turn,
// the others where they were: a strong cell_stiffness whose bulge a local
// fit leaves near 0 is started at bulge -0.3 too, and the best short fit
// costs no more than the fit from the start it was given.
TEST(MultiStart, EachParameterOfAnEffectIsStartedOverItsRange) {
  testing_support::ScratchDir scratch("multi");
  ModelParams truth = testing_support::true_tiny_baseline();
  truth.effects = {"cell_stiffness"};
  truth.effect_parameters["cell_stiffness"] = {{"grad_x", 0.28}, {"grad_y", 0.0}, {"bulge", -0.28}};
  const Dataset d = testing_support::synthesize_tiny(scratch.path, truth);
  ModelParams start = with_effects(testing_support::true_tiny_baseline(), {"cell_stiffness"});
  const auto parameters = fit_parameters({"cell_stiffness"});
  LeastSquaresOptions fit;
  const MultiStart range = multi_start(d, start, parameters, "cell_stiffness", fit, {4, 2});
  EXPECT_EQ(range.parameter, "cell_stiffness.grad_x,cell_stiffness.grad_y,cell_stiffness.bulge");
  ASSERT_EQ(range.tried.size(), 12u);
  for (int k = 0; k < 12; ++k) {
    const StartTried& t = range.tried[k];
    EXPECT_EQ(t.parameter, std::string("cell_stiffness.") + (k < 4 ? "grad_x" : k < 8 ? "grad_y" : "bulge"));
    EXPECT_GE(t.value, -0.3);
    EXPECT_LE(t.value, 0.3);
  }
  ASSERT_TRUE(range.found);
  LeastSquaresOptions short_fit = fit;
  short_fit.max_iterations = 2;
  const LeastSquaresResult from_start = fit_least_squares(d, start, parameters, short_fit);
  EXPECT_LE(range.best_sum_sq_mm2, from_start.sum_sq_mm2 * (1.0 + 1e-9));
  EXPECT_LT(parameter_value(range.best, parameters.back()), 0.0) << "the best start's bulge";
}

TEST(CalibDiagnoseStrong, AStrongStiffeningIsDiagnosedAsStiffening) {
  testing_support::ScratchDir scratch("stiff");
  ModelParams truth = testing_support::true_tiny_baseline();
  truth.effects = {"stiffening"};
  truth.effect_parameters["stiffening"] = {{"beta", kBeta}};
  const Dataset d = testing_support::synthesize_tiny(scratch.path, truth);
  DiagnoseOptions o;
  o.candidates = {"stiffening", "cell_stiffness", "sensor_tilt"};
  o.max_effects = 1;
  o.fit.least_squares.max_iterations = 10;
  const Diagnosis result = diagnose(d, ModelParams{}, o);
  ASSERT_EQ(result.verdict, std::vector<std::string>{"stiffening"}) << verdict_sentence(result);
  EXPECT_NEAR(result.final_params.effect_parameters.at("stiffening").at("beta"), kBeta, 0.25 * kBeta);
  EXPECT_NEAR(result.final_params.surface.spring_k, 58.0, 0.1 * 58.0);
  EXPECT_TRUE(result.goodness.explained) << fit_quality_sentence(result);
  for (const auto& c : result.ranking) {
    if (c.added == "stiffening") {
      EXPECT_TRUE(c.starts_tried.empty()) << c.starts_tried.size() << " starts tried";
    }
  }
}

}  // namespace
}  // namespace hj
