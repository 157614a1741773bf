// Leave-one-session-out error of a fitted model. Refitting from scratch for
// every fold would cost a full fit each; instead each fold starts from the
// full-data optimum (warm start) and takes one bounded Gauss-Newton step on
// the Jacobian there, with the held-out session's rows removed: exact for a
// model linear in its parameters, and close for these smooth ones. The
// held-out session is then replayed at the fold's parameters.
#pragma once

#include <vector>

#include "calib/least_squares.h"

namespace hj {

struct CrossValidation {
  double heldout_rmse_mm = 0.0;            // over all held-out samples
  std::vector<double> session_rmse_mm;     // each session when held out
  std::vector<ModelParams> fold_params;    // each fold's parameters
};

// @param fit  fit_least_squares on `dataset` with `parameters`
// Needs at least two sessions; with one, the held-out error is the fit's.
CrossValidation cross_validate(const Dataset& dataset, const std::vector<FitParameter>& parameters,
                               const LeastSquaresResult& fit, const ReplayOptions& options);

}  // namespace hj
