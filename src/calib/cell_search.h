// Where is a local defect? An effect with unfitted "row" and "col"
// parameters (cell_defect) acts on one cell, which no local fit can move
// between cells. Before its scan, each cell of the array is tried: the
// dataset is replayed with the effect in that cell at each probe of its
// fitted parameters (halfway to each bound, geometrically for a positive
// default: cell_defect's factor 0.45 and 2.24; a probe with no equilibrium,
// such as a soft cell folding under a baseline that absorbed the defect, is
// retried at half its step, down to 0.95 and 1.05). A probe is scored by the
// least-squares prediction along its direction with the current model's
// parameters re-solved along their Jacobian (the residuals projected off
// its columns): a baseline fitted to a soft cell has softened every
// spring, and a soft probe in the right cell only beats a stiff one
// elsewhere once k may rise again. Only the probe's direction counts, so a
// defect between the probes (0.6) is judged at its own size. The best 3
// cells by score are then fitted jointly for 4 iterations, from the
// predicted value and from the probe on its side, and the lowest cost
// gives the cell and the start of the scan and refit.
#pragma once

#include <limits>
#include <string>
#include <vector>

#include "calib/fit_parameters.h"
#include "calib/least_squares.h"

namespace hj {

// True if `effect` has the unfitted "row" and "col" parameters of a cell.
bool is_cell_effect(const std::string& effect);

struct CellSearch {
  ModelParams best;  // the start with the effect moved to the best cell and probe
  int row = -1, col = -1;
  double best_sum_sq_mm2 = 0.0;
  int replays = 0;
  std::string note;  // "cell_defect at cell [1, 2], factor 0.41 (best of 3 cells fitted; sum of squares -31.0 %)"
};

// @param start  the current model with `effect` switched on
// @param current  the current model's fit (its Jacobian and sum of squares)
// @param fit  the least-squares options of the short fits (and their replays)
// @param refine_below  the short fits run only if the best cell's predicted
//   sum of squares is below this (mm^2): where another effect's scan already
//   does far better, the best cell at its predicted value is start enough
// @throws std::runtime_error if no cell and probe replays, or no best cell's fit
CellSearch search_cells(const Dataset& dataset, const ModelParams& start, const std::vector<FitParameter>& parameters,
                        const std::string& effect, const LeastSquaresResult& current, const LeastSquaresOptions& fit,
                        double refine_below = std::numeric_limits<double>::infinity());

}  // namespace hj
