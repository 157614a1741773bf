// After the greedy selection: does the final model explain the data
// (goodness_of_fit.h), where does its residual concentrate, where is the
// missing effect (a chosen cell_defect's cell first), and how low did the
// best refitted candidate get?
#pragma once

#include "calib/diagnosis.h"

namespace hj {

// Fills out.goodness, final_pattern, worst_cells, best_rmse_mm and
// best_effects; out.verdict, final_params and pattern must be set.
void judge_final_model(const Dataset& dataset, const DiagnoseOptions& options, const LeastSquaresResult& final_fit,
                       Diagnosis& out);

}  // namespace hj
