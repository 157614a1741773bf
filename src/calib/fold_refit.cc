#include "calib/fold_refit.h"

#include <cmath>

#include "calib/dataset.h"
#include "calib/residuals.h"

namespace hj {

FoldRefit refit_fold(const Dataset& dataset, const std::vector<FitParameter>& parameters,
                     const LeastSquaresResult& fit, int held_out, const LeastSquaresOptions& options) {
  const MeasuredSession& held = dataset.sessions[held_out];
  const Dataset training = select_sessions(dataset, {held.session.name}, false);
  FoldRefit out;
  out.params = fit_least_squares(training, fit.params, parameters, options).params;
  const Eigen::VectorXd r = session_residuals(held, out.params, options.replay);
  out.heldout_count = static_cast<long>(r.size());
  out.heldout_rmse_mm = r.size() ? std::sqrt(r.squaredNorm() / r.size()) : 0.0;
  return out;
}

double pooled_heldout_rmse(const std::vector<double>& session_rmse_mm, const std::vector<int>& session_rows) {
  double sum_sq = 0.0;
  long n = 0;
  for (size_t s = 0; s < session_rmse_mm.size() && s + 1 < session_rows.size(); ++s) {
    const long count = session_rows[s + 1] - session_rows[s];
    sum_sq += session_rmse_mm[s] * session_rmse_mm[s] * count;
    n += count;
  }
  return n ? std::sqrt(sum_sq / n) : 0.0;
}

}  // namespace hj
