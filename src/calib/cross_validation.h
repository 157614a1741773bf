// Leave-one-session-out error of a fitted model. Refitting from scratch for
// every fold would cost a full fit each; instead each fold starts from the
// full-data optimum (warm start) and takes one bounded Gauss-Newton step on
// the Jacobian there, with the held-out session's rows removed: exact for a
// model linear in its parameters, and close for these smooth ones. The
// held-out session is then replayed at the fold's parameters.
//
// The step is checked on the training sessions. Where a parameter is only
// loosely held by them, the linear step can leap far along its flat valley
// to where the model no longer fits the training sessions either (synthetic
// stiffening + cell_stiffness: the screening's folds predicted a held-out
// 2.02 mm against the baseline's 1.60, where the refitted model's folds
// give 1.45). Such a fold is not a refit of anything, so the step is halved
// until it does not raise the training cost, as a refit's line search
// would, or dropped: the fold then keeps the full-data optimum.
#pragma once

#include <vector>

#include "calib/least_squares.h"

namespace hj {

struct CrossValidation {
  double heldout_rmse_mm = 0.0;            // over all held-out samples
  std::vector<double> session_rmse_mm;     // each session when held out
  std::vector<ModelParams> fold_params;    // each fold's parameters
  std::vector<double> fold_step;           // share of each fold's Gauss-Newton step taken: 1, 1/2, ... or 0
};

struct CrossValidationOptions {
  // Halvings of a fold's step that raises the training cost before the step
  // is dropped; -1: no check (the step as it is, no training replays). The
  // check replays the dataset at the optimum once, and each fold's training
  // sessions once per trial.
  int max_halvings = 3;
};

// @param fit  fit_least_squares on `dataset` with `parameters`, or a
//             linearisation laid out the same way (the screening's): the
//             training cost at its parameters is replayed, not read from
//             its residuals
// Needs at least two sessions; with one, the held-out error is the fit's.
CrossValidation cross_validate(const Dataset& dataset, const std::vector<FitParameter>& parameters,
                               const LeastSquaresResult& fit, const ReplayOptions& options,
                               const CrossValidationOptions& cv = {});

}  // namespace hj
