// All parameters jointly by bounded nonlinear least squares on the frame
// residuals (residuals.h: predicted - measured, every seen sample of every
// capture), with Ceres' Levenberg-Marquardt. The Jacobian is by forward
// differences, its columns and the sessions computed in parallel. Each
// parameter gets a standard error and a 95 % interval from the Gauss-Newton
// covariance s^2 (J^T J)^-1 at the optimum, s^2 = SSR / (n - p).
#pragma once

#include <Eigen/Core>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "calib/fit_parameters.h"
#include "calib/residuals.h"

namespace hj {

struct LeastSquaresOptions {
  int max_iterations = 20;
  double function_tolerance = 1e-5;  // relative change of the cost that ends the fit (1e-5 of 1.7e5 samples: about 2 mm^2)
  double difference_step = 3e-3;     // forward-difference step, relative to each parameter's scale
  // A parameter whose 95 % half-width exceeds this share of its value is
  // reported as only loosely constrained by the data.
  double loose_relative_halfwidth = 0.1;
  ReplayOptions replay = fitting_replay({});
  // False for a fit that is only a start (its parameters and cost are
  // used): no Jacobian is taken at the point it ends on, so the result's
  // `jacobian` is empty and its estimates' errors NaN. Ceres takes one after
  // every accepted step, so a 2-iteration fit saves one of its three.
  bool final_jacobian = true;
};

struct ParameterEstimate {
  FitParameter parameter;
  double value = 0.0;
  double std_error = 0.0;  // NaN if not estimated
  double ci95_low = 0.0;
  double ci95_high = 0.0;
  // false: moving it does not change any capture (e.g. the damping under a
  // static settle), so it is held at its start value and not estimated.
  bool active = true;
  bool at_bound = false;
  bool loose = false;
  // How ci95 was found: "linearised" (value +- 1.96 std_error, as above)
  // or "profile likelihood" (profile_likelihood.h). When not linearised,
  // the linearised interval is kept here (else NaN).
  std::string interval_method = "linearised";
  double linearised_low = std::numeric_limits<double>::quiet_NaN();
  double linearised_high = std::numeric_limits<double>::quiet_NaN();
  bool low_open = false, high_open = false;  // a profile end that reached the parameter's bound
};

struct LeastSquaresResult {
  ModelParams params;
  std::vector<ParameterEstimate> estimates;  // parallel to the parameters given
  long residual_count = 0;                   // n
  int free_parameters = 0;                   // p, the active ones
  double sum_sq_mm2 = 0.0;
  double rmse_mm = 0.0;
  double r2 = 0.0;  // 1 - SSR / SST over all compared samples, as the paper reports it
  int iterations = 0;
  int jacobians = 0;
  // Replays of the whole dataset at a point (each Jacobian adds one per
  // active parameter more, its difference columns).
  int evaluations = 0;
  std::string termination;
  // Ceres ended by a tolerance (or nothing was free), not by the iteration
  // cap or a failure: a model compared with another must have converged,
  // or the other is credited with its unfinished descent.
  bool converged = false;
  // Ceres ran out of iterations (still descending), as against converging or failing.
  bool stopped_at_cap = false;
  // At the optimum, for cross-validation without refitting from scratch:
  // the residuals (n), the Jacobian (n x p) in the scaled variables
  // u = value / scale of the active parameters, and each session's first
  // row (session_rows[s] .. session_rows[s + 1]).
  Eigen::VectorXd residuals;
  Eigen::MatrixXd jacobian;
  Eigen::VectorXd scale;
  std::vector<int> active;  // indices into estimates
  std::vector<int> session_rows;
};

// Called after each iteration: iteration, the most there may be, the RMSE.
using LeastSquaresProgress = std::function<void(int iteration, int max_iterations, double rmse_mm)>;

// @throws std::invalid_argument if the dataset has no samples or a start
//         value lies outside its parameter's bounds (naming it).
LeastSquaresResult fit_least_squares(const Dataset& dataset, const ModelParams& start,
                                     const std::vector<FitParameter>& parameters, const LeastSquaresOptions& options,
                                     const LeastSquaresProgress& progress = {});

// The options of a fit that is only a start for another (a multi-start's or
// the cell search's short fits): `iterations` iterations and no Jacobian at
// the end (final_jacobian).
LeastSquaresOptions start_fit_options(LeastSquaresOptions options, int iterations);

// The residuals of every session stacked in dataset order, and the first
// row of each (rows.size() == sessions + 1). Sessions run in parallel.
Eigen::VectorXd dataset_residuals(const Dataset& dataset, const ModelParams& params, const ReplayOptions& options,
                                  std::vector<int>* rows = nullptr);

// The first residual row of each capture, in the order the residuals are
// laid out (session by session, capture by capture, the measured samples),
// and the total at the end: the clusters of parameter_covariance().
std::vector<long> capture_rows(const Dataset& dataset);

// The covariance (p x p) of the parameters behind `jacobian` (n x p) at
// residuals r (n), whose rows form clusters [cluster_rows[c],
// cluster_rows[c + 1]) (one per capture): per parameter the larger of the
// Gauss-Newton variance s^2 (J^T J)^-1, s^2 = |r|^2 / (n - p), and the
// cluster-robust (sandwich) one, (J^T J)^-1 (sum_c J_c^T r_c r_c^T J_c)
// (J^T J)^-1 C / (C - p). Without clusters (fewer than p + 1, or rows not
// covering 0..n) only the first.
Eigen::MatrixXd parameter_covariance(const Eigen::MatrixXd& jacobian, const Eigen::VectorXd& residuals,
                                     const std::vector<long>& cluster_rows);

}  // namespace hj
