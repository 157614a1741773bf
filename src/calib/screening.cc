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

}  // namespace

ScreeningPrediction screen_effect(const Dataset& dataset, const LeastSquaresResult& current,
                                  const std::vector<FitParameter>& parameters, const ModelParams& start,
                                  const std::string& effect, const LeastSquaresOptions& options) {
  ScreeningPrediction out;
  out.effect = effect;
  out.params = start;
  const std::vector<int>& rows = current.session_rows;
  const int sessions = static_cast<int>(dataset.sessions.size());
  const long n = current.residuals.size();
  if (static_cast<int>(rows.size()) != sessions + 1 || rows.back() != n)
    throw std::invalid_argument("screening: the current fit does not belong to this dataset");

  // r at the start, keeping each session's settled states for the columns.
  std::vector<ReplayTrace> traces(sessions);
  Eigen::VectorXd r0(n);
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
  out.replays = 1;

  // The effect's own columns, in the scaled variables u = value / scale.
  std::vector<int> own;
  for (int j = 0; j < static_cast<int>(parameters.size()); ++j)
    if (!parameters[j].surface && parameters[j].effect == effect) own.push_back(j);
  const int k_own = static_cast<int>(own.size());
  std::vector<double> value(k_own), scale(k_own), step(k_own);
  for (int k = 0; k < k_own; ++k) {
    const FitParameter& p = parameters[own[k]];
    value[k] = parameter_value(start, p);
    scale[k] = parameter_scale(p, value[k]);
    const double h = options.difference_step * scale[k];
    step[k] = value[k] + h <= p.spec.upper ? h : -h;
  }
  Eigen::MatrixXd columns(n, k_own);
  std::vector<std::atomic<bool>> failed(k_own);
  auto column_jobs = [&](const std::vector<int>& which) {
    const int count = static_cast<int>(which.size()) * sessions;
    parallel_for(
        count,
        [&](int job) {
          const int k = which[job / sessions], s = job % sessions;
          ModelParams moved = start;
          set_parameter_value(moved, parameters[own[k]], value[k] + step[k]);
          try {
            columns.col(k).segment(rows[s], rows[s + 1] - rows[s]) =
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
      step[k] = -step[k];
      retry.push_back(k);
    }
  if (!retry.empty()) column_jobs(retry);
  std::vector<int> kept;  // columns that change something
  for (int k = 0; k < k_own; ++k) {
    if (failed[k]) continue;
    columns.col(k) = (columns.col(k) - r0) / (step[k] / scale[k]);
    if (columns.col(k).cwiseAbs().maxCoeff() > 0.0) kept.push_back(k);
  }

  // [current model's active columns | the effect's kept columns].
  const int p_base = static_cast<int>(current.active.size());
  const int p = p_base + static_cast<int>(kept.size());
  Eigen::MatrixXd j(n, p);
  if (p_base) j.leftCols(p_base) = current.jacobian;
  for (size_t k = 0; k < kept.size(); ++k) j.col(p_base + k) = columns.col(kept[k]);

  // One Gauss-Newton step; an effect parameter that would leave its bounds
  // is held at the bound and the others solved again. The current model's
  // parameters are not held (a step that carries one past its bound is
  // flagged below instead: holding them changed which candidates the
  // held-out check kept on the synthetic matrix).
  Eigen::VectorXd lo = Eigen::VectorXd::Constant(p, -std::numeric_limits<double>::infinity());
  Eigen::VectorXd hi = Eigen::VectorXd::Constant(p, std::numeric_limits<double>::infinity());
  for (size_t k = 0; k < kept.size(); ++k) {
    const FitParameter& param = parameters[own[kept[k]]];
    lo[p_base + k] = (param.spec.lower - value[kept[k]]) / scale[kept[k]];
    hi[p_base + k] = (param.spec.upper - value[kept[k]]) / scale[kept[k]];
  }
  const Eigen::VectorXd d = bounded_gauss_newton_step(j, r0, lo, hi);
  const Eigen::VectorXd r1 = r0 + j * d;

  for (int k = 0; k < p_base; ++k) {
    const FitParameter& param = parameters[current.active[k]];
    const double v = parameter_value(start, param) + d[k] * current.scale[k];
    set_parameter_value(out.params, param, std::clamp(std::isfinite(v) ? v : parameter_value(start, param),
                                                      param.spec.lower, param.spec.upper));
    // A current-model parameter the step takes from inside its bounds
    // onto or past one.
    const double from = parameter_value(start, param);
    if ((v <= param.spec.lower && from > param.spec.lower) || (v >= param.spec.upper && from < param.spec.upper))
      out.bounds_reached.push_back(param.qualified_name());
  }
  for (size_t k = 0; k < kept.size(); ++k) {
    const FitParameter& param = parameters[own[kept[k]]];
    const double v = value[kept[k]] + d[p_base + k] * scale[kept[k]];
    set_parameter_value(out.params, param, std::clamp(v, param.spec.lower, param.spec.upper));
  }
  out.residual_count = n;
  out.free_parameters = p;
  out.sum_sq_mm2 = r1.squaredNorm();
  out.rmse_mm = std::sqrt(out.sum_sq_mm2 / std::max(n, 1L));
  out.heldout_rmse_mm = linear_heldout_rmse(j, r1, rows);
  out.reference_heldout_rmse_mm = linear_heldout_rmse(current.jacobian, current.residuals, rows);
  out.residuals = r1;
  out.scale.resize(p);
  out.active = current.active;
  for (int k = 0; k < p_base; ++k) out.scale[k] = current.scale[k];
  for (size_t k = 0; k < kept.size(); ++k) {
    out.scale[p_base + k] = scale[kept[k]];
    out.active.push_back(own[kept[k]]);
  }
  out.jacobian = std::move(j);
  return out;
}

}  // namespace hj
