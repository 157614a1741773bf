// An effect far stronger than the synthetic matrix's is found as reliably
// as a small one: a strain stiffening with beta near its upper range
// (tension several times the linear spring's at the sweep's largest
// stretches), which the baseline absorbs into a stiffer k, is diagnosed as
// stiffening with diagnose's defaults. Its local refit explains the data,
// so the search over beta's range (calib/multi_start.h), which runs where a
// local refit leaves the data unexplained, is not paid for here.
#include <gtest/gtest.h>

#include "calib/diagnosis.h"
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
