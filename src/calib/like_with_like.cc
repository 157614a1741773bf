#include "calib/like_with_like.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace hj {

ModelParams without_effect(ModelParams candidate, const std::string& added) {
  candidate.effects.erase(std::remove(candidate.effects.begin(), candidate.effects.end(), added),
                          candidate.effects.end());
  candidate.effect_parameters.erase(added);
  return candidate;
}

LikeWithLike refit_from_candidate_optimum(const Dataset& dataset, const LeastSquaresResult& current,
                                          const std::vector<FitParameter>& current_parameters,
                                          const ModelParams& candidate, const std::string& added, double min_gain,
                                          const LeastSquaresOptions& options,
                                          const LeastSquaresProgress& progress) {
  LikeWithLike out;
  const ModelParams start = without_effect(candidate, added);
  try {
    const Eigen::VectorXd r = dataset_residuals(dataset, start, options.replay);
    out.stripped_rmse_mm = std::sqrt(r.squaredNorm() / std::max<Eigen::Index>(r.size(), 1));
  } catch (const SettleInterrupted&) {
    throw;  // the caller stopped the work: not a failed replay
  } catch (const std::exception&) {
    out.stripped_rmse_mm = std::numeric_limits<double>::quiet_NaN();
    return out;
  }
  // The same margin an effect must gain in-sample: less is the difference
  // between a cold replay and the fit's warm-started one, or a valley's
  // last few hundredths.
  if (!(out.stripped_rmse_mm <= (1.0 - min_gain) * current.rmse_mm)) return out;
  try {
    out.refit = fit_least_squares(dataset, start, current_parameters, options, progress);
  } catch (const SettleInterrupted&) {
    throw;
  } catch (const std::exception&) {
    // A start the fit cannot begin from: the current fit stands.
  }
  return out;
}

}  // namespace hj
