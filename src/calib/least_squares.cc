#include "calib/least_squares.h"

#include <ceres/ceres.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <atomic>
#include <functional>
#include <stdexcept>

#include "calib/parallel_for.h"

namespace hj {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// The residuals and their Jacobian as functions of the scaled variables
// u_j = value_j / scale_j of the active parameters. Keeps the last point
// evaluated with its Jacobian, as Ceres asks for it again at each start.
class ScaledModel {
 public:
  ScaledModel(const Dataset& dataset, ModelParams base, std::vector<FitParameter> parameters, Eigen::VectorXd scale,
              const LeastSquaresOptions& options)
      : dataset_(dataset), base_(std::move(base)), parameters_(std::move(parameters)), scale_(std::move(scale)),
        options_(options) {
    rows_.push_back(0);
    for (const auto& s : dataset.sessions) rows_.push_back(rows_.back() + residual_count(s));
  }

  int residual_count_all() const { return rows_.back(); }
  int parameter_count() const { return static_cast<int>(parameters_.size()); }
  const std::vector<int>& rows() const { return rows_; }

  ModelParams params_at(const Eigen::VectorXd& u) const {
    ModelParams p = base_;
    for (int j = 0; j < parameter_count(); ++j) set_parameter_value(p, parameters_[j], value_at(u, j));
    return p;
  }

  // Parameter j's value at u. Ceres keeps u[j] within bound / scale, but
  // u[j] * scale can round past the bound, and a fit started there refuses it.
  double value_at(const Eigen::VectorXd& u, int j) const {
    const ParameterSpec& spec = parameters_[j].spec;
    return std::clamp(u[j] * scale_[j], spec.lower, spec.upper);
  }

  // r(u) (n), and if jacobian, J (n x p); true if every replay succeeded.
  // Every replay starts each settle from the cached point's settled states;
  // the difference columns from those of u itself.
  bool evaluate(const Eigen::VectorXd& u, Eigen::VectorXd& r, Eigen::MatrixXd* jacobian) {
    if (have_cache_ && u == cache_u_) {
      r = cache_r_;
      if (jacobian) *jacobian = cache_j_;
      return true;
    }
    // Ceres evaluates the line search's point, then the same point again
    // as its candidate: the residuals of the last point are kept too.
    if (!jacobian && have_last_ && u == last_u_) {
      r = last_r_;
      return true;
    }
    const int p = parameter_count(), sessions = static_cast<int>(dataset_.sessions.size());
    std::vector<ReplayTrace> traces(sessions);
    ++evaluations_;
    r.resize(residual_count_all());
    if (!run(sessions, [&](int s) {
          r.segment(rows_[s], rows_[s + 1] - rows_[s]) = session_residuals(
              dataset_.sessions[s], params_at(u), options_.replay, hint(s), &traces[s]);
        }))
      return false;
    have_last_ = true;
    last_u_ = u;
    last_r_ = r;
    if (!jacobian) return true;
    Eigen::MatrixXd values(residual_count_all(), p);
    std::vector<double> steps(p);
    for (int j = 0; j < p; ++j) {
      // Step away from the upper bound if a forward step would cross it.
      const double h = options_.difference_step;
      steps[j] = u[j] + h <= parameters_[j].spec.upper / scale_[j] ? h : -h;
    }
    // A column whose step leaves the region where the model settles is
    // taken by the opposite step.
    std::vector<std::atomic<bool>> failed(p);
    auto column = [&](int job) {
      const int j = job / sessions, s = job % sessions;
      Eigen::VectorXd point = u;
      point[j] += steps[j];
      try {
        values.col(j).segment(rows_[s], rows_[s + 1] - rows_[s]) =
            session_residuals(dataset_.sessions[s], params_at(point), options_.replay, &traces[s]);
      } catch (const SettleInterrupted&) {
        throw;  // the caller stopped the work: not a failed replay
      } catch (const std::exception&) {
        failed[j] = true;
      }
    };
    run(p * sessions, column);
    std::vector<int> retry;
    for (int j = 0; j < p; ++j)
      if (failed[j]) {
        failed[j] = false;
        steps[j] = -steps[j];
        retry.push_back(j);
      }
    if (!retry.empty()) {
      run(static_cast<int>(retry.size()) * sessions,
          [&](int job) { column(retry[job / sessions] * sessions + job % sessions); });
      for (int j : retry)
        if (failed[j]) return false;
    }
    jacobian->resize(residual_count_all(), p);
    for (int j = 0; j < p; ++j) jacobian->col(j) = (values.col(j) - r) / steps[j];
    seed(u, r, *jacobian);
    cache_traces_ = std::move(traces);
    ++jacobians_;
    return true;
  }

  int jacobians() const { return jacobians_; }
  int evaluations() const { return evaluations_; }

  // Takes r and J at u from elsewhere (the probe over all parameters).
  const std::vector<ReplayTrace>& traces() const { return cache_traces_; }
  void seed_traces(std::vector<ReplayTrace> traces) { cache_traces_ = std::move(traces); }

  void seed(const Eigen::VectorXd& u, const Eigen::VectorXd& r, const Eigen::MatrixXd& jacobian) {
    have_cache_ = true;
    cache_u_ = u;
    cache_r_ = r;
    cache_j_ = jacobian;
  }

 private:
  // Runs jobs in parallel; false if a replay failed (no equilibrium).
  bool run(int count, const std::function<void(int)>& job) {
    std::atomic<bool> ok{true};
    parallel_for(
        count,
        [&](int i) {
          try {
            job(i);
          } catch (const SettleInterrupted&) {
            throw;  // the caller stopped the work: not a failed replay
          } catch (const std::exception&) {
            ok = false;
          }
        },
        options_.replay.threads);
    return ok;
  }

  const ReplayTrace* hint(int session) const {
    return session_trace(&cache_traces_, session);
  }

  const Dataset& dataset_;
  ModelParams base_;
  std::vector<FitParameter> parameters_;
  Eigen::VectorXd scale_;
  LeastSquaresOptions options_;
  std::vector<int> rows_;
  bool have_cache_ = false;
  Eigen::VectorXd cache_u_, cache_r_;
  bool have_last_ = false;
  Eigen::VectorXd last_u_, last_r_;  // the last point evaluated, residuals only
  Eigen::MatrixXd cache_j_;
  std::vector<ReplayTrace> cache_traces_;  // per session, at cache_u_
  int jacobians_ = 0;
  int evaluations_ = 0;
};

// The last iteration Ceres has finished (its callbacks run after each, the
// start's iteration 0 too), and whether the Jacobian asked for at the fit's
// last one was left out.
struct IterationCount : public ceres::IterationCallback {
  int finished = -1;
  bool final_jacobian_skipped = false;
  ceres::CallbackReturnType operator()(const ceres::IterationSummary& summary) override {
    finished = summary.iteration;
    return ceres::SOLVER_CONTINUE;
  }
};

class DatasetCost : public ceres::CostFunction {
 public:
  // skip_after: with count, the Jacobian Ceres asks for in this iteration
  // (after its last accepted step) is zeros and costs no replay (0: none).
  DatasetCost(ScaledModel& model, IterationCount& count, int skip_after)
      : model_(model), count_(count), skip_after_(skip_after) {
    set_num_residuals(model.residual_count_all());
    mutable_parameter_block_sizes()->push_back(model.parameter_count());
  }

  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    const Eigen::VectorXd u = Eigen::Map<const Eigen::VectorXd>(parameters[0], model_.parameter_count());
    Eigen::VectorXd r;
    Eigen::MatrixXd j;
    bool want_j = jacobians && jacobians[0];
    if (want_j && skip_after_ > 0 && count_.finished + 1 >= skip_after_) {
      // Asked after the last step: the iteration cap ends the fit before
      // Ceres could use it (a zero gradient cannot move the point).
      want_j = false;
      count_.final_jacobian_skipped = true;
      Eigen::Map<Eigen::VectorXd>(jacobians[0], num_residuals() * model_.parameter_count()).setZero();
    }
    // An interruption must not unwind through Ceres: the evaluation fails,
    // the callback ends the solve, and fit_least_squares throws after it.
    try {
      if (!model_.evaluate(u, r, want_j ? &j : nullptr)) return false;
    } catch (const SettleInterrupted&) {
      return false;
    }
    Eigen::Map<Eigen::VectorXd>(residuals, r.size()) = r;
    if (want_j)
      Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(jacobians[0], j.rows(),
                                                                                          j.cols()) = j;
    return true;
  }

 private:
  ScaledModel& model_;
  IterationCount& count_;
  int skip_after_;
};

class ProgressCallback : public ceres::IterationCallback {
 public:
  ProgressCallback(const LeastSquaresProgress& progress, int max_iterations, long n, const ReplayOptions& replay)
      : progress_(progress), max_(max_iterations), n_(n), replay_(replay) {}
  ceres::CallbackReturnType operator()(const ceres::IterationSummary& summary) override {
    if (is_interrupted(replay_)) return ceres::SOLVER_ABORT;
    if (progress_) progress_(summary.iteration, max_, std::sqrt(2.0 * summary.cost / std::max(n_, 1L)));
    return ceres::SOLVER_CONTINUE;
  }

 private:
  const LeastSquaresProgress& progress_;
  int max_;
  long n_;
  const ReplayOptions& replay_;
};

double parameter_scale(const FitParameter& p, double start) {
  return std::max({std::abs(start), std::abs(p.spec.default_value), 1e-3 * (p.spec.upper - p.spec.lower), 1e-12});
}

// SST of the measured heights over the samples in the residual layout.
double total_sum_of_squares(const Dataset& dataset) {
  double sum = 0.0, sum_sq = 0.0;
  long n = 0;
  for (const auto& s : dataset.sessions)
    for (const auto& c : s.captures)
      for (Eigen::Index k = 0; k < c.heights_mm.size(); ++k) {
        const double h = c.heights_mm.data()[k];
        if (std::isnan(h)) continue;
        sum += h;
        sum_sq += h * h;
        ++n;
      }
  return n ? sum_sq - sum * sum / n : 0.0;
}

}  // namespace

std::vector<long> capture_rows(const Dataset& dataset) {
  std::vector<long> rows = {0};
  for (const auto& session : dataset.sessions)
    for (const auto& capture : session.captures)
      rows.push_back(rows.back() + static_cast<long>((capture.heights_mm.array() == capture.heights_mm.array()).count()));
  return rows;
}

LeastSquaresOptions start_fit_options(LeastSquaresOptions options, int iterations) {
  options.max_iterations = iterations;
  options.final_jacobian = false;
  return options;
}

Eigen::VectorXd dataset_residuals(const Dataset& dataset, const ModelParams& params, const ReplayOptions& options,
                                  std::vector<int>* rows) {
  std::vector<int> offsets{0};
  for (const auto& s : dataset.sessions) offsets.push_back(offsets.back() + residual_count(s));
  Eigen::VectorXd out(offsets.back());
  parallel_for(
      static_cast<int>(dataset.sessions.size()),
      [&](int s) {
        out.segment(offsets[s], offsets[s + 1] - offsets[s]) = session_residuals(dataset.sessions[s], params, options);
      },
      options.threads);
  if (rows) *rows = offsets;
  return out;
}

LeastSquaresResult fit_least_squares(const Dataset& dataset, const ModelParams& start,
                                     const std::vector<FitParameter>& parameters, const LeastSquaresOptions& options,
                                     const LeastSquaresProgress& progress) {
  LeastSquaresResult out;
  out.params = start;
  const int all = static_cast<int>(parameters.size());
  Eigen::VectorXd scale(all), u0(all);
  for (int j = 0; j < all; ++j) {
    const FitParameter& p = parameters[j];
    const double v = parameter_value(start, p);
    if (!(v >= p.spec.lower && v <= p.spec.upper))
      throw std::invalid_argument("start value of " + p.qualified_name() + " = " + std::to_string(v) +
                                  " is outside its bounds");
    scale[j] = parameter_scale(p, v);
    u0[j] = v / scale[j];
    out.estimates.push_back({p, v, kNaN, kNaN, kNaN});
  }

  // A first Jacobian over all parameters finds those that change nothing.
  ScaledModel probe(dataset, start, parameters, scale, options);
  if (probe.residual_count_all() == 0) throw std::invalid_argument("the dataset has no measured samples");
  Eigen::VectorXd r0;
  Eigen::MatrixXd j0;
  if (!probe.evaluate(u0, r0, &j0)) throw std::runtime_error("the model fails to replay the dataset at the start values");
  std::vector<FitParameter> active;
  for (int j = 0; j < all; ++j)
    if (j0.col(j).cwiseAbs().maxCoeff() > 0.0) {
      out.active.push_back(j);
      active.push_back(parameters[j]);
    } else {
      out.estimates[j].active = false;
    }
  const int p = static_cast<int>(active.size());
  Eigen::VectorXd scale_a(p), u(p);
  Eigen::MatrixXd j_active(j0.rows(), p);
  for (int k = 0; k < p; ++k) {
    scale_a[k] = scale[out.active[k]];
    u[k] = u0[out.active[k]];
    j_active.col(k) = j0.col(out.active[k]);
  }
  ScaledModel model(dataset, start, active, scale_a, options);
  model.seed(u, r0, j_active);  // Ceres starts by asking for this point again
  model.seed_traces(probe.traces());
  if (progress) progress(0, options.max_iterations, std::sqrt(r0.squaredNorm() / std::max<long>(r0.size(), 1)));
  out.residual_count = model.residual_count_all();
  out.free_parameters = p;
  out.converged = p == 0;  // nothing free: nothing to converge

  IterationCount iteration_count;
  if (p > 0) {
    ceres::Problem::Options problem_options;
    problem_options.cost_function_ownership = ceres::TAKE_OWNERSHIP;
    ceres::Problem problem(problem_options);
    problem.AddResidualBlock(
        new DatasetCost(model, iteration_count, options.final_jacobian ? 0 : options.max_iterations), nullptr,
        u.data());
    for (int k = 0; k < p; ++k) {
      problem.SetParameterLowerBound(u.data(), k, active[k].spec.lower / scale_a[k]);
      problem.SetParameterUpperBound(u.data(), k, active[k].spec.upper / scale_a[k]);
    }
    ceres::Solver::Options solver_options;
    solver_options.linear_solver_type = ceres::DENSE_QR;
    solver_options.max_num_iterations = options.max_iterations;
    solver_options.function_tolerance = options.function_tolerance;
    // With bounds, every iteration of Ceres' trust region runs a projected
    // Armijo line search along its step. Its default cubic interpolation
    // asks for the gradient at every trial point, i.e. a whole Jacobian
    // (1 + p replays of the dataset) per trial, and near a bifurcation
    // (kappa_jam's second equilibrium) it contracts many times: most of a
    // fit's time went there. Quadratic interpolation needs the cost only
    // (one replay per trial).
    solver_options.line_search_interpolation_type = ceres::QUADRATIC;
    solver_options.logging_type = ceres::SILENT;
    ProgressCallback callback(progress, options.max_iterations, out.residual_count, options.replay);
    solver_options.callbacks.push_back(&callback);
    solver_options.callbacks.push_back(&iteration_count);
    ceres::Solver::Summary summary;
    ceres::Solve(solver_options, &problem, &summary);
    throw_if_interrupted(options.replay);
    out.iterations = static_cast<int>(summary.iterations.size());
    out.termination = summary.BriefReport();
    out.converged = summary.termination_type == ceres::CONVERGENCE;
    out.stopped_at_cap = summary.termination_type == ceres::NO_CONVERGENCE;
    if (iteration_count.final_jacobian_skipped) out.converged = false, out.stopped_at_cap = true;
  }

  // The optimum's residuals and Jacobian (cached if Ceres ended on one).
  const bool with_jacobian = options.final_jacobian || p == 0;
  if (!model.evaluate(u, out.residuals, with_jacobian ? &out.jacobian : nullptr))
    throw std::runtime_error("the model fails to replay the dataset at the fitted values");
  out.jacobians = probe.jacobians() + model.jacobians();
  out.evaluations = probe.evaluations() + model.evaluations();
  out.scale = scale_a;
  out.session_rows = model.rows();
  out.params = model.params_at(u);
  out.sum_sq_mm2 = out.residuals.squaredNorm();
  out.rmse_mm = std::sqrt(out.sum_sq_mm2 / out.residual_count);
  const double sst = total_sum_of_squares(dataset);
  out.r2 = sst > 0.0 ? 1.0 - out.sum_sq_mm2 / sst : kNaN;

  const Eigen::MatrixXd covariance =
      with_jacobian ? parameter_covariance(out.jacobian, out.residuals, capture_rows(dataset))
                    : Eigen::MatrixXd::Constant(p, p, kNaN);
  for (int k = 0; k < p; ++k) {
    ParameterEstimate& e = out.estimates[out.active[k]];
    e.value = model.value_at(u, k);
    e.std_error = std::sqrt(std::max(covariance(k, k), 0.0)) * scale_a[k];
    e.ci95_low = e.value - 1.96 * e.std_error;
    e.ci95_high = e.value + 1.96 * e.std_error;
    const double span = e.parameter.spec.upper - e.parameter.spec.lower;
    e.at_bound = std::abs(e.value - e.parameter.spec.lower) < 1e-9 * span ||
                 std::abs(e.value - e.parameter.spec.upper) < 1e-9 * span;
    e.loose = 1.96 * e.std_error > options.loose_relative_halfwidth * std::abs(e.value);
  }
  return out;
}

Eigen::MatrixXd parameter_covariance(const Eigen::MatrixXd& jacobian, const Eigen::VectorXd& residuals,
                                     const std::vector<long>& cluster_rows) {
  const long n = residuals.size();
  const int p = static_cast<int>(jacobian.cols());
  if (p == 0) return {};
  // Gauss-Newton covariance, inverted on the eigenvalues that are not
  // negligible so that an unidentifiable direction shows as a huge error.
  const double variance = residuals.squaredNorm() / std::max<long>(n - p, 1);
  const Eigen::MatrixXd jtj = jacobian.transpose() * jacobian;
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(jtj);
  const double largest = eigen.eigenvalues().cwiseAbs().maxCoeff();
  Eigen::VectorXd inverse(p);
  for (int k = 0; k < p; ++k) {
    const double e = eigen.eigenvalues()[k];
    inverse[k] = e > 1e-14 * largest ? 1.0 / e : 1e30;
  }
  const Eigen::MatrixXd bread = eigen.eigenvectors() * inverse.asDiagonal() * eigen.eigenvectors().transpose();
  Eigen::MatrixXd covariance = variance * bread;
  // The samples of one capture are not independent: where the model misses,
  // it misses by a smooth surface over the whole frame. The classic
  // covariance counts every sample as independent evidence and so can be
  // far too narrow for a parameter that only a few captures inform
  // (kappa_jam). The cluster-robust (sandwich) covariance treats each
  // capture as one cluster; each parameter keeps the larger variance.
  const long clusters = static_cast<long>(cluster_rows.size()) - 1;
  if (clusters <= p || cluster_rows.front() != 0 || cluster_rows.back() != n) return covariance;
  Eigen::MatrixXd meat = Eigen::MatrixXd::Zero(p, p);
  for (long c = 0; c < clusters; ++c) {
    const long rows = cluster_rows[c + 1] - cluster_rows[c];
    const Eigen::VectorXd g =
        jacobian.middleRows(cluster_rows[c], rows).transpose() * residuals.segment(cluster_rows[c], rows);
    meat += g * g.transpose();
  }
  const Eigen::MatrixXd robust = bread * meat * bread * (double(clusters) / double(clusters - p));
  for (int k = 0; k < p; ++k)
    if (robust(k, k) > covariance(k, k) && covariance(k, k) > 0.0) {
      const double factor = std::sqrt(robust(k, k) / covariance(k, k));
      covariance.row(k) *= factor;
      covariance.col(k) *= factor;
    }
  return covariance;
}

}  // namespace hj
