// A one-cell manufacturing defect (cell_defect: one cell's springs softer)
// is found and localised: diagnose searches the cells (calib/cell_search.h),
// chooses cell_defect over the smooth cell_stiffness field and a camera
// tilt, names the cell first among the worst and says in words which cell
// and by how much.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

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

// Defects whose size lies between the cell search's probes (0.45 and 2.24)
// or beyond them, in an inner and a corner cell: each is placed in its own
// cell and fitted near its factor.
struct Defect {
  int row, col;
  double factor;
};

void PrintTo(const Defect& d, std::ostream* out) {
  *out << "cell [" << d.row << ", " << d.col << "] at " << d.factor << " k";
}

class CalibDiagnoseDefectMatrix : public ::testing::TestWithParam<Defect> {};

TEST_P(CalibDiagnoseDefectMatrix, TheDefectIsPlacedInItsCellAndFitted) {
  const Defect truth_defect = GetParam();
  testing_support::ScratchDir scratch("defect");
  ModelParams truth = testing_support::true_tiny_baseline();
  truth.effects = {"cell_defect"};
  truth.effect_parameters["cell_defect"] = {
      {"factor", truth_defect.factor}, {"row", truth_defect.row}, {"col", truth_defect.col}};
  const Dataset d = testing_support::synthesize_tiny(scratch.path, truth);
  DiagnoseOptions o;
  o.candidates = {"cell_defect"};
  o.max_effects = 1;
  o.fit.least_squares.max_iterations = 10;
  const Diagnosis result = diagnose(d, ModelParams{}, o);
  ASSERT_EQ(result.verdict, std::vector<std::string>{"cell_defect"}) << verdict_sentence(result);
  ASSERT_FALSE(result.ranking.empty());
  const std::string search = result.ranking.front().scan_note;
  const auto& defect = result.final_params.effect_parameters.at("cell_defect");
  EXPECT_EQ(defect.at("row"), truth_defect.row) << search;
  EXPECT_EQ(defect.at("col"), truth_defect.col) << search;
  EXPECT_NEAR(std::log(defect.at("factor")), std::log(truth_defect.factor), std::log(1.15));
  EXPECT_TRUE(result.goodness.explained) << fit_quality_sentence(result);
}

INSTANTIATE_TEST_SUITE_P(BetweenAndBeyondTheProbes, CalibDiagnoseDefectMatrix,
                         ::testing::Values(Defect{1, 1, 0.6}, Defect{2, 3, 3.0}, Defect{0, 1, 1.6}),
                         [](const ::testing::TestParamInfo<Defect>& info) {
                           const Defect& d = info.param;
                           return "Cell" + std::to_string(d.row) + std::to_string(d.col) + "At" +
                                  std::to_string(static_cast<int>(std::lround(10 * d.factor))) + "Tenths";
                         });

}  // namespace
}  // namespace hj
