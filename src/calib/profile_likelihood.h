// Profile-likelihood 95 % intervals for parameters that the linearised
// (Gauss-Newton / sandwich, symmetric) interval describes badly: where the
// cost is flat and lopsided in a parameter (the jammed bending stiffness: a
// stiffer jam changes the surface less and less), +- 1.96 standard errors
// is too narrow on the flat side and too wide on the steep one.
//
// The statistic. SSR(theta) is the least sum of squared residuals with the
// profiled parameter held at theta and every other free parameter refitted.
// The interval is {theta : SSR(theta) - SSR_min <= chi2_1(0.95) s^2 D}, with
// s^2 = SSR_min / (n - p) and D the design effect of the profiled parameter:
// the ratio of the variance parameter_covariance() reports for it (the
// larger of the Gauss-Newton and the capture-clustered sandwich variance)
// to its Gauss-Newton variance, D >= 1. The samples of one capture share
// the model's miss, so they are worth fewer independent ones; dividing the
// cost rise by D is counting the evidence in effective independent
// captures. For a model linear in its parameters this interval is exactly
// the linearised one, value +- 1.96 standard errors; it differs where the
// model is not linear.
#pragma once

#include <Eigen/Core>
#include <functional>
#include <string>
#include <vector>

#include "calib/least_squares.h"

namespace hj {

// chi^2 with one degree of freedom, 95 % point (= 1.96^2).
inline constexpr double kChi2OneDof95 = 3.841458820694124;

// The cost rise that bounds the interval for parameter k of a fit with this
// Jacobian and these residuals (cluster_rows as for parameter_covariance).
double profile_threshold(const Eigen::MatrixXd& jacobian, const Eigen::VectorXd& residuals,
                         const std::vector<long>& cluster_rows, int k);

// The one-dimensional search, independent of what the cost is.
struct ProfileSearch {
  double value = 0.0;      // the optimum
  double min_cost = 0.0;   // SSR there
  double threshold = 0.0;  // the allowed rise (profile_threshold)
  double step = 0.0;       // first step out from the optimum (the linearised half-width)
  double lower = 0.0, upper = 0.0;  // the parameter's bounds
  double tolerance = 0.0;  // the search ends when the bracket of an end is this narrow
  int max_doublings = 8;   // the bracketing step doubles at most this often
};

struct ProfileInterval {
  double low = 0.0, high = 0.0;
  bool low_open = false, high_open = false;  // the cost stays within the threshold up to the bound
  int evaluations = 0;
  double threshold = 0.0;
};

// Called after each evaluation of the profile: evaluations so far, side
// (-1 low, +1 high), the value tried, its cost rise over the threshold.
using ProfileProgress = std::function<void(int evaluations, int side, double value, double rise_ratio)>;

// Cost at a value of the profiled parameter, the others refitted; side says
// which end is being searched (-1 low, +1 high), for a warm start. May
// throw (no equilibrium there): that value counts as outside.
using ProfileCost = std::function<double(double value, int side)>;

// For each side: steps out from the optimum (step, then doubling it) until
// the cost rises past the threshold or the bound is reached, then bisects
// the bracket, each time at the point where the signed root
// sqrt(rise / threshold) interpolates to 1, kept within the bracket's
// middle 80 %, until it is narrower than the tolerance or an end's signed
// root is within 2 % of 1; the end is the interpolated crossing of the
// final bracket. Next to a value the model cannot replay, the end is the
// last value it could.
ProfileInterval profile_interval(const ProfileCost& cost, const ProfileSearch& search,
                                 const ProfileProgress& progress = {});

struct ProfileOptions {
  // Chord (fixed-Jacobian Gauss-Newton) steps refitting the other
  // parameters at each profile point, each one replay of the dataset.
  int refit_iterations = 2;
  double relative_tolerance = 0.05;  // of the linearised half-width
};

// Replaces the linearised 95 % interval of each active parameter of `fit`
// (the result of fit_least_squares on `dataset` with `parameters`) that is
// loose, or at whose linearised ends the cost, the others held, rises by
// less than half the threshold (the model is not linear there, e.g. next to
// a jump; two replays a parameter), by
// its profile interval (search: profile_interval from the linearised
// half-width; the others refitted at each point by chord steps with the
// fit's Jacobian, warm-started), sets interval_method to "profile likelihood" and
// keeps the linearised one in linearised_low/high. `loose` is then judged
// on the profile interval. Parameters whose qualified name is in `also` are
// profiled even when not loose.
// @throws std::invalid_argument naming a name of `also` that is no active
//         parameter of the fit.
using ParameterProfileProgress = std::function<void(const std::string& parameter, int evaluations, const std::string& detail)>;
void profile_loose_parameters(const Dataset& dataset, const std::vector<FitParameter>& parameters,
                              const LeastSquaresOptions& fit_options, const ProfileOptions& options,
                              LeastSquaresResult& fit, const ParameterProfileProgress& progress = {},
                              const std::vector<std::string>& also = {});

}  // namespace hj
