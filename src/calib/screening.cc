#include "calib/screening.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "calib/bounded_step.h"
#include "calib/parallel_for.h"

namespace hj {

namespace {

// As least_squares.cc scales its variables.
double parameter_scale(const FitParameter& p, double start) {
  return std::max({std::abs(start), std::abs(p.spec.default_value), 1e-3 * (p.spec.upper - p.spec.lower), 1e-12});
}

// Leave-one-session-out RMSE of the linearised model r(d) = r + J d at its
// optimum: each fold one Gauss-Newton step on the other sessions' rows,
// the held-out rows predicted by the same linearisation (no replay).
double linear_heldout_rmse(const Eigen::MatrixXd& j, const Eigen::VectorXd& r, const std::vector<int>& rows) {
  const int sessions = static_cast<int>(rows.size()) - 1;
  if (sessions < 2 || j.cols() == 0) return std::sqrt(r.squaredNorm() / std::max<Eigen::Index>(r.size(), 1));
  const Eigen::MatrixXd jtj = j.transpose() * j;
  const Eigen::VectorXd jtr = j.transpose() * r;
  double sum_sq = 0.0;
  for (int s = 0; s < sessions; ++s) {
    const int begin = rows[s], count = rows[s + 1] - rows[s];
    const auto j_held = j.middleRows(begin, count);
    const auto r_held = r.segment(begin, count);
    Eigen::MatrixXd a = jtj - j_held.transpose() * j_held;
    a.diagonal() *= 1.0 + 1e-6;
    const Eigen::VectorXd step = -a.ldlt().solve(jtr - j_held.transpose() * r_held);
    sum_sq += (r_held + j_held * (step.allFinite() ? step : Eigen::VectorXd::Zero(step.size()))).squaredNorm();
  }
  return std::sqrt(sum_sq / std::max<Eigen::Index>(r.size(), 1));
}

// The effect's own Jacobian columns at the start, in the scaled variables
// u = value / scale, by forward differences from warm-started replays.
struct EffectColumns {
  std::vector<int> own;                 // the effect's parameters, as indices into `parameters`
  std::vector<double> value, scale, step;  // per own parameter
  Eigen::MatrixXd columns;              // (n x own.size()); a failed one is not in `kept`
  std::vector<int> kept;                // own columns that change something
  int replays = 0;                      // replays of the dataset they took
};

// r at the start, keeping each session's settled states for the columns.
Eigen::VectorXd start_residuals(const Dataset& dataset, const ModelParams& start, const std::vector<int>& rows,
                                const std::string& effect, const LeastSquaresOptions& options,
                                std::vector<ReplayTrace>& traces) {
  const int sessions = static_cast<int>(dataset.sessions.size());
  Eigen::VectorXd r0(rows.back());
  try {
    parallel_for(
        sessions,
        [&](int s) {
          r0.segment(rows[s], rows[s + 1] - rows[s]) =
              session_residuals(dataset.sessions[s], start, options.replay, nullptr, &traces[s]);
        },
        options.replay.threads);
  } catch (const SettleInterrupted&) {
    throw;  // the caller stopped the work: not a failed replay
  } catch (const std::exception& e) {
    throw std::runtime_error("the model fails to replay the dataset with " + effect + " at its start values: " +
                             e.what());
  }
  return r0;
}

// The difference step of each own parameter, inward from its upper bound.
EffectColumns effect_difference_steps(const std::vector<FitParameter>& parameters, const ModelParams& start,
                                   const std::string& effect, const LeastSquaresOptions& options) {
  EffectColumns out;
  for (int j = 0; j < static_cast<int>(parameters.size()); ++j)
    if (!parameters[j].surface && parameters[j].effect == effect) out.own.push_back(j);
  const int k_own = static_cast<int>(out.own.size());
  out.value.resize(k_own);
  out.scale.resize(k_own);
  out.step.resize(k_own);
  for (int k = 0; k < k_own; ++k) {
    const FitParameter& p = parameters[out.own[k]];
    out.value[k] = parameter_value(start, p);
    out.scale[k] = parameter_scale(p, out.value[k]);
    const double h = options.difference_step * out.scale[k];
    out.step[k] = out.value[k] + h <= p.spec.upper ? h : -h;
  }
  return out;
}

EffectColumns effect_columns(const Dataset& dataset, const std::vector<FitParameter>& parameters,
                             const ModelParams& start, const std::string& effect, const std::vector<int>& rows,
                             const Eigen::VectorXd& r0, std::vector<ReplayTrace>& traces,
                             const LeastSquaresOptions& options) {
  EffectColumns out = effect_difference_steps(parameters, start, effect, options);
  const int sessions = static_cast<int>(dataset.sessions.size());
  const int k_own = static_cast<int>(out.own.size());
  out.columns.resize(r0.size(), k_own);
  std::vector<std::atomic<bool>> failed(k_own);
  auto column_jobs = [&](const std::vector<int>& which) {
    const int count = static_cast<int>(which.size()) * sessions;
    parallel_for(
        count,
        [&](int job) {
          const int k = which[job / sessions], s = job % sessions;
          ModelParams moved = start;
          set_parameter_value(moved, parameters[out.own[k]], out.value[k] + out.step[k]);
          try {
            out.columns.col(k).segment(rows[s], rows[s + 1] - rows[s]) =
                session_residuals(dataset.sessions[s], moved, options.replay, &traces[s]);
          } catch (const SettleInterrupted&) {
            throw;  // the caller stopped the work: not a failed replay
          } catch (const std::exception&) {
            failed[k] = true;
          }
        },
        options.replay.threads);
    out.replays += static_cast<int>(which.size());
  };
  std::vector<int> all(k_own);
  for (int k = 0; k < k_own; ++k) all[k] = k;
  column_jobs(all);
  std::vector<int> retry;  // a step that leaves where the model settles: the opposite one
  for (int k = 0; k < k_own; ++k)
    if (failed[k]) {
      failed[k] = false;
      out.step[k] = -out.step[k];
      retry.push_back(k);
    }
  if (!retry.empty()) column_jobs(retry);
  for (int k = 0; k < k_own; ++k) {
    if (failed[k]) continue;
    out.columns.col(k) = (out.columns.col(k) - r0) / (out.step[k] / out.scale[k]);
    if (out.columns.col(k).cwiseAbs().maxCoeff() > 0.0) out.kept.push_back(k);
  }
  return out;
}

// [current model's active columns | the effect's kept columns].
Eigen::MatrixXd joined_jacobian(const LeastSquaresResult& current, const EffectColumns& e) {
  const int p_base = static_cast<int>(current.active.size());
  const int p = p_base + static_cast<int>(e.kept.size());
  Eigen::MatrixXd j(e.columns.rows(), p);
  if (p_base) j.leftCols(p_base) = current.jacobian;
  for (size_t k = 0; k < e.kept.size(); ++k) j.col(p_base + k) = e.columns.col(e.kept[k]);
  return j;
}

// One Gauss-Newton step; an effect parameter that would leave its bounds is
// held at the bound and the others solved again. The current model's
// parameters are not held (a step that carries one past its bound is
// flagged in apply_step instead).
Eigen::VectorXd screening_step(const Eigen::MatrixXd& j, const Eigen::VectorXd& r0, int p_base,
                               const std::vector<FitParameter>& parameters, const EffectColumns& e) {
  const Eigen::Index p = j.cols();
  Eigen::VectorXd lo = Eigen::VectorXd::Constant(p, -std::numeric_limits<double>::infinity());
  Eigen::VectorXd hi = Eigen::VectorXd::Constant(p, std::numeric_limits<double>::infinity());
  for (size_t k = 0; k < e.kept.size(); ++k) {
    const FitParameter& param = parameters[e.own[e.kept[k]]];
    lo[p_base + k] = (param.spec.lower - e.value[e.kept[k]]) / e.scale[e.kept[k]];
    hi[p_base + k] = (param.spec.upper - e.value[e.kept[k]]) / e.scale[e.kept[k]];
  }
  return bounded_gauss_newton_step(j, r0, lo, hi);
}

// The parameters after step d, clamped to their bounds, into out.params;
// a current-model parameter the step takes from inside its bounds onto or
// past one is named in out.bounds_reached.
void apply_step(const Eigen::VectorXd& d, const LeastSquaresResult& current, const ModelParams& start,
                const std::vector<FitParameter>& parameters, const EffectColumns& e, ScreeningPrediction& out) {
  const int p_base = static_cast<int>(current.active.size());
  for (int k = 0; k < p_base; ++k) {
    const FitParameter& param = parameters[current.active[k]];
    const double v = parameter_value(start, param) + d[k] * current.scale[k];
    set_parameter_value(out.params, param, std::clamp(std::isfinite(v) ? v : parameter_value(start, param),
                                                      param.spec.lower, param.spec.upper));
    const double from = parameter_value(start, param);
    if ((v <= param.spec.lower && from > param.spec.lower) || (v >= param.spec.upper && from < param.spec.upper))
      out.bounds_reached.push_back(param.qualified_name());
  }
  for (size_t k = 0; k < e.kept.size(); ++k) {
    const FitParameter& param = parameters[e.own[e.kept[k]]];
    const double v = e.value[e.kept[k]] + d[p_base + k] * e.scale[e.kept[k]];
    set_parameter_value(out.params, param, std::clamp(v, param.spec.lower, param.spec.upper));
  }
}

// The predicted figures and the linearisation (residuals r1, Jacobian j,
// scales, active columns) cross_validate() needs.
void record_prediction(const LeastSquaresResult& current, const EffectColumns& e, const std::vector<int>& rows,
                       Eigen::MatrixXd j, Eigen::VectorXd r1, ScreeningPrediction& out) {
  const long n = r1.size();
  const int p_base = static_cast<int>(current.active.size());
  const int p = static_cast<int>(j.cols());
  out.residual_count = n;
  out.free_parameters = p;
  out.sum_sq_mm2 = r1.squaredNorm();
  out.rmse_mm = std::sqrt(out.sum_sq_mm2 / std::max(n, 1L));
  out.heldout_rmse_mm = linear_heldout_rmse(j, r1, rows);
  out.reference_heldout_rmse_mm = linear_heldout_rmse(current.jacobian, current.residuals, rows);
  out.residuals = std::move(r1);
  out.scale.resize(p);
  out.active = current.active;
  for (int k = 0; k < p_base; ++k) out.scale[k] = current.scale[k];
  for (size_t k = 0; k < e.kept.size(); ++k) {
    out.scale[p_base + k] = e.scale[e.kept[k]];
    out.active.push_back(e.own[e.kept[k]]);
  }
  out.jacobian = std::move(j);
}

}  // namespace

ScreeningPrediction screen_effect(const Dataset& dataset, const LeastSquaresResult& current,
                                  const std::vector<FitParameter>& parameters, const ModelParams& start,
                                  const std::string& effect, const LeastSquaresOptions& options) {
  ScreeningPrediction out;
  out.effect = effect;
  out.params = start;
  const std::vector<int>& rows = current.session_rows;
  const int sessions = static_cast<int>(dataset.sessions.size());
  if (static_cast<int>(rows.size()) != sessions + 1 || rows.back() != current.residuals.size())
    throw std::invalid_argument("screening: the current fit does not belong to this dataset");
  std::vector<ReplayTrace> traces(sessions);
  const Eigen::VectorXd r0 = start_residuals(dataset, start, rows, effect, options, traces);
  const EffectColumns columns = effect_columns(dataset, parameters, start, effect, rows, r0, traces, options);
  out.replays = 1 + columns.replays;
  Eigen::MatrixXd j = joined_jacobian(current, columns);
  const int p_base = static_cast<int>(current.active.size());
  const Eigen::VectorXd d = screening_step(j, r0, p_base, parameters, columns);
  Eigen::VectorXd r1 = r0 + j * d;
  apply_step(d, current, start, parameters, columns, out);
  record_prediction(current, columns, rows, std::move(j), std::move(r1), out);
  return out;
}

}  // namespace hj
