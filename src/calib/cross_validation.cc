#include "calib/cross_validation.h"

#include <algorithm>
#include <cmath>

#include "calib/bounded_step.h"
#include "calib/parallel_for.h"

namespace hj {

namespace {

// The fold's Gauss-Newton step from the optimum on the training rows, in
// the fit's scaled variables, each parameter kept inside its bounds (empty
// if nothing is free).
Eigen::VectorXd fold_step(const std::vector<FitParameter>& parameters, const LeastSquaresResult& fit, int rows_begin,
                          int rows_end) {
  const int p = static_cast<int>(fit.active.size());
  if (p == 0) return {};
  const int n = static_cast<int>(fit.residuals.size());
  const int held = std::clamp(rows_end - rows_begin, 0, n);
  Eigen::MatrixXd j(n - held, p);
  Eigen::VectorXd r(n - held);
  j << fit.jacobian.topRows(rows_begin), fit.jacobian.bottomRows(n - rows_begin - held);
  r << fit.residuals.head(rows_begin), fit.residuals.tail(n - rows_begin - held);
  Eigen::VectorXd lo(p), hi(p);
  for (int k = 0; k < p; ++k) {
    const FitParameter& param = parameters[fit.active[k]];
    const double value = parameter_value(fit.params, param);
    lo[k] = (param.spec.lower - value) / fit.scale[k];
    hi[k] = (param.spec.upper - value) / fit.scale[k];
  }
  return bounded_gauss_newton_step(j, r, lo, hi);
}

// The optimum moved by t * step, clamped to the bounds.
ModelParams fold_parameters(const std::vector<FitParameter>& parameters, const LeastSquaresResult& fit,
                            const Eigen::VectorXd& step, double t) {
  ModelParams out = fit.params;
  for (int k = 0; k < static_cast<int>(step.size()); ++k) {
    const FitParameter& param = parameters[fit.active[k]];
    double value = parameter_value(fit.params, param) + t * step[k] * fit.scale[k];
    if (!std::isfinite(value)) value = parameter_value(fit.params, param);
    set_parameter_value(out, param, std::clamp(value, param.spec.lower, param.spec.upper));
  }
  return out;
}

// A session's sum of squares at `params`; infinity where the model finds no
// equilibrium. warm and trace as session_residuals takes them.
double session_cost(const MeasuredSession& session, const ModelParams& params, const ReplayOptions& options,
                    const ReplayTrace* warm = nullptr, ReplayTrace* trace = nullptr) {
  try {
    return session_residuals(session, params, options, warm, trace).squaredNorm();
  } catch (const SettleInterrupted&) {
    throw;  // the caller stopped the work: not a failed replay
  } catch (const std::exception&) {
    return INFINITY;
  }
}

}  // namespace

CrossValidation cross_validate(const Dataset& dataset, const std::vector<FitParameter>& parameters,
                               const LeastSquaresResult& fit, const ReplayOptions& options,
                               const CrossValidationOptions& cv) {
  const int sessions = static_cast<int>(dataset.sessions.size());
  CrossValidation out;
  out.session_rmse_mm.assign(sessions, 0.0);
  out.fold_params.assign(sessions, fit.params);
  out.fold_step.assign(sessions, 1.0);
  if (sessions < 2) {
    out.heldout_rmse_mm = fit.rmse_mm;
    return out;
  }
  // Each session's cost at the optimum, replayed as the trials are: a fit's
  // own residuals come from warm-started settles (or, for the screening,
  // from a linearisation). Where that replay fails, every trial passes (the
  // step is taken as it is). The trials and the held-out replays start from
  // these replays' moves (replay_session's warm start).
  const bool checked = cv.max_halvings >= 0 && !fit.active.empty();
  std::vector<double> at_optimum(sessions, 0.0);
  std::vector<ReplayTrace> optimum_traces(sessions);
  if (checked)
    parallel_for(
        sessions,
        [&](int s) {
          at_optimum[s] = session_cost(dataset.sessions[s], fit.params, options, nullptr, &optimum_traces[s]);
        },
        options.threads);
  const auto warm = [&](int s) { return session_trace(&optimum_traces, s); };
  std::vector<double> sum_sq(sessions, 0.0);
  std::vector<long> count(sessions, 0);
  parallel_for(
      sessions,
      [&](int s) {
        const Eigen::VectorXd step = fold_step(parameters, fit, fit.session_rows[s], fit.session_rows[s + 1]);
        out.fold_params[s] = fold_parameters(parameters, fit, step, 1.0);
        if (checked) {
          double optimum = 0.0;
          for (int other = 0; other < sessions; ++other)
            if (other != s) optimum += at_optimum[other];
          out.fold_params[s] = fit.params;
          out.fold_step[s] = 0.0;
          double t = 1.0;
          for (int h = 0; h <= cv.max_halvings; ++h, t *= 0.5) {
            const ModelParams trial = fold_parameters(parameters, fit, step, t);
            double cost = 0.0;
            for (int other = 0; other < sessions && cost <= optimum; ++other)
              if (other != s) cost += session_cost(dataset.sessions[other], trial, options, warm(other));
            if (cost <= optimum) {
              out.fold_params[s] = trial;
              out.fold_step[s] = t;
              break;
            }
          }
        }
        const Eigen::VectorXd r = session_residuals(dataset.sessions[s], out.fold_params[s], options, warm(s));
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
