// A one-cell manufacturing defect (cell_defect: one cell's springs softer)
// is found and localised: diagnose searches the cells (calib/cell_search.h),
// chooses cell_defect over the smooth cell_stiffness field and a camera
// tilt, names the cell first among the worst and says in words which cell
// and by how much.
#include <gtest/gtest.h>

#include "calib/diagnosis.h"
#include "calib/report/diagnose_report_html.h"
#include "calib_synthetic.h"
#include "scratch_dir.h"

namespace hj {
namespace {

TEST(CalibDiagnoseDefect, ASoftCellIsFoundAndLocalised) {
  testing_support::ScratchDir scratch("soft-cell");
  ModelParams truth = testing_support::true_tiny_baseline();
  truth.effects = {"cell_defect"};
  truth.effect_parameters["cell_defect"] = {{"factor", 0.4}, {"row", 1}, {"col", 2}};
  const Dataset d = testing_support::synthesize_tiny(scratch.path, truth);
  DiagnoseOptions o;
  o.candidates = {"cell_defect", "cell_stiffness", "sensor_tilt"};
  o.max_effects = 1;
  o.fit.least_squares.max_iterations = 10;
  const Diagnosis result = diagnose(d, ModelParams{}, o);
  ASSERT_TRUE(result.skipped.empty()) << ::testing::PrintToString(result.skipped);
  ASSERT_EQ(result.verdict, std::vector<std::string>{"cell_defect"}) << verdict_sentence(result);
  const auto& defect = result.final_params.effect_parameters.at("cell_defect");
  EXPECT_EQ(defect.at("row"), 1.0);
  EXPECT_EQ(defect.at("col"), 2.0);
  EXPECT_NEAR(defect.at("factor"), 0.4, 0.08);
  // The baseline's own residual spreads from the soft cell (its worst cell
  // may be a neighbour); the located cell comes first.
  ASSERT_FALSE(result.worst_cells.empty());
  EXPECT_EQ(result.worst_cells[0], std::make_pair(1, 2));
  EXPECT_TRUE(result.goodness.explained) << fit_quality_sentence(result);
  const std::string verdict = verdict_sentence(result);
  EXPECT_NE(verdict.find("cell [1, 2] at 0."), std::string::npos) << verdict;
  EXPECT_NE(verdict.find("softer"), std::string::npos) << verdict;
}

}  // namespace
}  // namespace hj
