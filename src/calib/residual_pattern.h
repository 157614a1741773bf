// Where a model's residual concentrates, in words a user can act on: the
// worst cells, and the RMSE of the samples near pinned nodes, near the
// clamped edge, in jammed cells and at high pressure against the rest.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "calib/residuals.h"

namespace hj {

struct ResidualSplit {
  std::string name;   // "near pinned nodes", ...
  std::string other;  // "elsewhere", ...
  double rmse_mm = 0.0, other_rmse_mm = 0.0;  // NaN without samples
  long samples = 0, other_samples = 0;
};

struct ResidualPattern {
  std::vector<std::pair<int, int>> worst_cells;  // (r, c), worst first
  std::vector<double> worst_cell_rmse_mm;
  std::vector<ResidualSplit> splits;
  std::vector<std::string> findings;  // sentences
};

// `evaluation` is evaluate_dataset(dataset, ...). A split is worth a
// sentence when one side's RMSE is at least 1.25 times the other's.
// @param worst  how many cells to list
ResidualPattern describe_residuals(const Dataset& dataset, const Evaluation& evaluation, int worst = 3);

}  // namespace hj
