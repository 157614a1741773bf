#include "calib/final_model.h"

#include <algorithm>
#include <cmath>

#include "calib/cell_search.h"

namespace hj {

void judge_final_model(const Dataset& dataset, const DiagnoseOptions& options, const LeastSquaresResult& final_fit,
                       Diagnosis& out) {
  out.goodness = goodness_of_fit(final_fit, out.noise_floor_mm, options.goodness);
  out.final_pattern = out.verdict.empty()
                          ? out.pattern
                          : describe_residuals(dataset, evaluate_dataset(dataset, final_fit.params,
                                                                         options.fit.least_squares.replay));
  for (const auto& e : out.verdict)
    if (is_cell_effect(e)) {
      const auto& v = out.final_params.effect_parameters.at(e);
      out.worst_cells.push_back({static_cast<int>(std::lround(v.at("row"))), static_cast<int>(std::lround(v.at("col")))});
    }
  for (const auto& cell : out.pattern.worst_cells)
    if (out.worst_cells.size() < out.pattern.worst_cells.size() &&
        std::find(out.worst_cells.begin(), out.worst_cells.end(), cell) == out.worst_cells.end())
      out.worst_cells.push_back(cell);
  out.best_rmse_mm = final_fit.rmse_mm;
  out.best_effects = out.verdict;
  for (const auto* record : {&out.ranking, &out.later_rounds})
    for (const CandidateFit& c : *record)
      if (!c.screened_out && std::isfinite(c.fit.rmse_mm) && c.fit.rmse_mm < out.best_rmse_mm) {
        out.best_rmse_mm = c.fit.rmse_mm;
        out.best_effects = c.effects;
      }
}

}  // namespace hj
