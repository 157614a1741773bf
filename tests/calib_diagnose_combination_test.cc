// Two effects at once, one physical and one of the pressure regulator, are
// found together on a tiny dataset: a jammed-cell contraction with a gain
// and offset. On the matrix's three sessions the contraction's fit absorbs
// the offset into the mass, and the pair is found only from the offset's
// own earlier optimum (candidate_refit.cc); these two short sessions do not
// set that trap, so this guards the combination, not that mechanism.
#include <gtest/gtest.h>

#include <algorithm>

#include "calib/diagnosis.h"
#include "calib/report/diagnose_report_html.h"
#include "calib_synthetic.h"
#include "scratch_dir.h"

namespace hj {
namespace {

TEST(CalibDiagnoseCombination, AnOffsetAnotherEffectAbsorbedIsFoundWithIt) {
  testing_support::ScratchDir scratch("contraction-offset");
  ModelParams truth = testing_support::true_tiny_baseline();
  truth.effects = {"jam_contraction", "pressure_offset"};
  truth.effect_parameters["jam_contraction"] = {{"contraction", 0.05}};
  truth.effect_parameters["pressure_offset"] = {{"gain", 1.05}, {"offset_pa", 40.0}};
  const Dataset d = testing_support::synthesize_tiny(scratch.path, truth);
  DiagnoseOptions o;
  o.candidates = {"jam_contraction", "pressure_offset"};
  const Diagnosis result = diagnose(d, ModelParams{}, o);
  std::vector<std::string> verdict = result.verdict;
  std::sort(verdict.begin(), verdict.end());
  EXPECT_EQ(verdict, (std::vector<std::string>{"jam_contraction", "pressure_offset"}))
      << fit_quality_sentence(result) << "\n" << ::testing::PrintToString(result.notes);
  EXPECT_TRUE(result.goodness.explained) << fit_quality_sentence(result);
  ASSERT_TRUE(result.final_params.effect_parameters.count("pressure_offset"));
  EXPECT_NEAR(result.final_params.effect_parameters.at("pressure_offset").at("offset_pa"), 40.0, 10.0);
  EXPECT_NEAR(result.final_params.surface.mass_kg, 0.52, 0.03);
}

}  // namespace
}  // namespace hj
