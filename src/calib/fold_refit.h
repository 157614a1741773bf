// The leave-one-session-out figures of cross_validation.h are one
// Gauss-Newton step per fold, standing for a refit. Where a fold's step runs
// along a direction its training sessions leave loose without raising their
// cost, its held-out replay can be far off what the refit gives (synthetic
// stiffening + cell_stiffness: paper-sequence held out at 4.05 mm after the
// step, 1.08 mm after a real refit without it). Here a fold is refitted for
// real, from the full-data optimum, on its training sessions only.
#pragma once

#include <vector>

#include "calib/least_squares.h"

namespace hj {

struct FoldRefit {
  ModelParams params;           // the fold's refitted parameters
  double heldout_rmse_mm = 0.0; // the held-out session replayed there
  long heldout_count = 0;       // its samples
};

// Fits `parameters` on every session of `dataset` but `held_out`, from
// fit.params, and replays the held-out session there.
FoldRefit refit_fold(const Dataset& dataset, const std::vector<FitParameter>& parameters,
                     const LeastSquaresResult& fit, int held_out, const LeastSquaresOptions& options);

// The held-out RMSE over all sessions from each session's held-out RMSE and
// its sample count (fit.session_rows).
double pooled_heldout_rmse(const std::vector<double>& session_rmse_mm, const std::vector<int>& session_rows);

}  // namespace hj
