#include "calib/cross_validation.h"

#include <Eigen/Cholesky>
#include <cmath>

#include "calib/parallel_for.h"

namespace hj {

namespace {

// The fold's parameters: one Gauss-Newton step from the optimum on the
// training rows, clamped to the bounds.
ModelParams fold_parameters(const std::vector<FitParameter>& parameters, const LeastSquaresResult& fit, int rows_begin,
                            int rows_end) {
  const int p = static_cast<int>(fit.active.size());
  if (p == 0) return fit.params;
  const int n = static_cast<int>(fit.residuals.size());
  Eigen::MatrixXd jtj = fit.jacobian.transpose() * fit.jacobian;
  Eigen::VectorXd jtr = fit.jacobian.transpose() * fit.residuals;
  const int held = rows_end - rows_begin;
  if (held > 0 && held < n) {
    const auto j_held = fit.jacobian.middleRows(rows_begin, held);
    jtj -= j_held.transpose() * j_held;
    jtr -= j_held.transpose() * fit.residuals.segment(rows_begin, held);
  }
  // A little Levenberg damping keeps a nearly flat direction from leaping.
  jtj.diagonal() *= 1.0 + 1e-6;
  const Eigen::VectorXd step = -jtj.ldlt().solve(jtr);
  ModelParams out = fit.params;
  for (int k = 0; k < p; ++k) {
    const FitParameter& param = parameters[fit.active[k]];
    double value = parameter_value(fit.params, param) + step[k] * fit.scale[k];
    if (!std::isfinite(value)) value = parameter_value(fit.params, param);
    set_parameter_value(out, param, std::clamp(value, param.spec.lower, param.spec.upper));
  }
  return out;
}

}  // namespace

CrossValidation cross_validate(const Dataset& dataset, const std::vector<FitParameter>& parameters,
                               const LeastSquaresResult& fit, const ReplayOptions& options) {
  const int sessions = static_cast<int>(dataset.sessions.size());
  CrossValidation out;
  out.session_rmse_mm.assign(sessions, 0.0);
  out.fold_params.assign(sessions, fit.params);
  if (sessions < 2) {
    out.heldout_rmse_mm = fit.rmse_mm;
    return out;
  }
  std::vector<double> sum_sq(sessions, 0.0);
  std::vector<long> count(sessions, 0);
  parallel_for(
      sessions,
      [&](int s) {
        out.fold_params[s] = fold_parameters(parameters, fit, fit.session_rows[s], fit.session_rows[s + 1]);
        const Eigen::VectorXd r = session_residuals(dataset.sessions[s], out.fold_params[s], options);
        sum_sq[s] = r.squaredNorm();
        count[s] = r.size();
        out.session_rmse_mm[s] = r.size() ? std::sqrt(sum_sq[s] / r.size()) : 0.0;
      },
      options.threads);
  double total = 0.0;
  long n = 0;
  for (int s = 0; s < sessions; ++s) {
    total += sum_sq[s];
    n += count[s];
  }
  out.heldout_rmse_mm = n ? std::sqrt(total / n) : 0.0;
  return out;
}

}  // namespace hj
