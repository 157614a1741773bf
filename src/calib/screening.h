// Screening a candidate effect without refitting: at the current model's
// optimum, with the effect switched on at its start values, only the
// effect's own Jacobian columns are computed (warm-started replays); one
// Gauss-Newton step on [current model's columns | effect's columns]
// predicts the cost the full refit would reach, and the same linearisation
// predicts the leave-one-session-out error (cross_validation.h) without any
// replay. A candidate whose predicted figures could not pass the
// acceptance is not refitted (diagnosis.h).
#pragma once

#include <string>
#include <vector>

#include "calib/least_squares.h"

namespace hj {

struct ScreeningPrediction {
  std::string effect;
  ModelParams params;            // the current optimum plus the predicted step
  long residual_count = 0;       // n
  int free_parameters = 0;       // p: the current model's active ones plus the effect's
  double sum_sq_mm2 = 0.0;       // predicted SSR after the step
  double rmse_mm = 0.0;
  double heldout_rmse_mm = 0.0;  // predicted leave-one-session-out RMSE
  // The current model's leave-one-session-out RMSE by the same
  // linearisation: the predicted held-out gain is judged against this, so
  // that the linearisation's own error cancels.
  double reference_heldout_rmse_mm = 0.0;
  int replays = 0;               // whole-dataset replays it cost
  // Current-model parameters the step carried from inside their bounds
  // onto one: a step that long is beyond what the linearisation can
  // predict, so the screening does not rule the candidate out on it.
  std::vector<std::string> bounds_reached;
  // The linearisation itself, laid out as LeastSquaresResult's optimum
  // fields (residuals after the step, Jacobian, scale, active indices into
  // `parameters`), so that cross_validate() can check the held-out
  // prediction by replaying the held-out sessions.
  Eigen::VectorXd residuals;
  Eigen::MatrixXd jacobian;
  Eigen::VectorXd scale;
  std::vector<int> active;
};

// @param current     fit_least_squares of the current model (its residuals,
//                    Jacobian, scale and active columns at the optimum)
// @param parameters  fit_parameters(current effects + effect); the current
//                    model's parameters come first, in the same order
// @param start       the current optimum with `effect` switched on at the
//                    values its full refit would start from
// @throws std::runtime_error if the model cannot replay the dataset at
//         `start`
ScreeningPrediction screen_effect(const Dataset& dataset, const LeastSquaresResult& current,
                                  const std::vector<FitParameter>& parameters, const ModelParams& start,
                                  const std::string& effect, const LeastSquaresOptions& options);

}  // namespace hj
