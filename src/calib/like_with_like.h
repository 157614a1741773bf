// Like with like: is a candidate's gain its effect's, or did its refit only
// find a better optimum of the model it extends? A candidate's refit starts
// from the current optimum and moves every parameter, so it can leave a
// side basin the current model's own fit is stuck in and be credited with
// the whole drop (synthetic sensor_tilt: baseline + sensor_tilt stuck at
// kappa_jam 39, 1.119 mm; pressure_offset's refit went to kappa_jam 1.8 and
// 1.04 mm with gain 0.999 and offset 0.85 Pa, i.e. switched off, and was
// chosen as a second effect). The current model is replayed at the
// candidate's optimum with the added effect switched off; if it fits better
// there by a real margin, it is refitted from there, and the candidates are
// judged against that fit instead.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "calib/least_squares.h"

namespace hj {

// `candidate` with `added` switched off (absent from effects and values):
// the model it extends, at the candidate's values of that model's
// parameters.
ModelParams without_effect(ModelParams candidate, const std::string& added);

struct LikeWithLike {
  // The current model's RMSE replayed at the candidate's optimum with the
  // added effect off; NaN if that replay fails.
  double stripped_rmse_mm = 0.0;
  // The current model refitted from there, if the replay beat the current
  // fit's RMSE by min_gain of it (else empty: nothing to recheck).
  std::optional<LeastSquaresResult> refit;
};

// current_parameters: fit_parameters() of the current model's effects.
// SettleInterrupted is let through; a refit that fails is left empty.
LikeWithLike refit_from_candidate_optimum(const Dataset& dataset, const LeastSquaresResult& current,
                                          const std::vector<FitParameter>& current_parameters,
                                          const ModelParams& candidate, const std::string& added, double min_gain,
                                          const LeastSquaresOptions& options,
                                          const LeastSquaresProgress& progress = {});

}  // namespace hj
