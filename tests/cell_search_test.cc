// The cell search (calib/cell_search.h) places a soft cell in its own cell
// when the current model has absorbed the defect: a baseline fitted without
// it has soft jammed cells (kappa_jam far below the truth), and the search's
// soft probe in the right cell folds the mesh at the top of a jammed sweep.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "calib/cell_search.h"
#include "calib/synthesize.h"
#include "calib_synthetic.h"
#include "scratch_dir.h"

namespace hj {
namespace {

// Every cell jammed level, then raised to the device's top pressure.
void write_jammed_sweep(const std::filesystem::path& dir) {
  using nlohmann::json;
  json steps = json::array({{{"op", "capture"}, {"frame", "frames/000.csv"}}, {{"op", "set_pressure"}, {"kpa", 0.59}},
                            {{"op", "set_pressure"}, {"kpa", 0.295}}});
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) steps.push_back({{"op", "jam"}, {"cell", {r, c}}});
  int frame = 1;
  for (double kpa : {0.0, 1.725, 3.45}) {
    steps.push_back({{"op", "set_pressure"}, {"kpa", kpa}});
    steps.push_back({{"op", "capture"}, {"frame", "frames/00" + std::to_string(frame++) + ".csv"}});
  }
  std::filesystem::create_directories(dir / "jammed-sweep");
  std::ofstream(dir / "jammed-sweep" / "session.json") << testing_support::tiny_session_json("jammed-sweep", steps).dump(1);
}

TEST(CellSearch, FindsASoftCellThatABaselineWithSoftJammedCellsAbsorbed) {
  testing_support::ScratchDir scratch("cell-search");
  testing_support::write_tiny_sessions(scratch.path / "sessions");
  write_jammed_sweep(scratch.path / "sessions");
  ModelParams truth = testing_support::true_tiny_baseline();
  truth.effects = {"cell_defect"};
  truth.effect_parameters["cell_defect"] = {{"factor", 0.6}, {"row", 1}, {"col", 1}};
  synthesize_dataset(scratch.path / "sessions", scratch.path / "data", truth, SynthOptions{});
  const Dataset dataset = read_dataset(scratch.path / "data");

  // The baseline a fit without the defect reaches on such data.
  ModelParams absorbed = testing_support::true_tiny_baseline();
  absorbed.surface.kappa_jam = 0.16;
  absorbed.surface.spring_k = 54.0;
  LeastSquaresOptions fit;
  fit.max_iterations = 1;
  const LeastSquaresResult current = fit_least_squares(dataset, absorbed, fit_parameters({}), fit);
  const std::vector<FitParameter> parameters = fit_parameters({"cell_defect"});
  const CellSearch found = search_cells(dataset, with_effects(current.params, {"cell_defect"}), parameters,
                                        "cell_defect", current, LeastSquaresOptions{});
  EXPECT_EQ(found.row, 1) << found.note;
  EXPECT_EQ(found.col, 1) << found.note;
  EXPECT_LT(found.best.effect_parameters.at("cell_defect").at("factor"), 1.0) << found.note;
  EXPECT_LT(found.best_sum_sq_mm2, current.sum_sq_mm2) << found.note;
}

}  // namespace
}  // namespace hj
