// A full fit of a model to a dataset, the paper's way then jointly: the mass
// from the levelling pressure (levelling.h), the spring stiffness by
// Algorithm 1 (stiffness_bisection.h), mass and spring stiffness refined on
// the bare captures, the jammed bending stiffness by Algorithm 1, then every
// parameter of the baseline and the switched-on effects by bounded least
// squares (least_squares.h) from there.
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "calib/least_squares.h"
#include "calib/levelling.h"
#include "calib/optimum_probe.h"
#include "calib/profile_likelihood.h"
#include "calib/stiffness_bisection.h"

namespace hj {

struct FitOptions {
  bool initial_estimates = true;  // levelling and Algorithm 1 before the joint fit
  BisectionOptions bisection;
  LeastSquaresOptions least_squares;
  // After the joint fit, replace the linearised interval of each loosely
  // constrained parameter by its profile-likelihood interval
  // (profile_likelihood.h); costs a few warm-started refits per end.
  bool profile_loose = false;
  // After the joint fit, probe each free parameter a few standard errors
  // away (optimum_probe.h) and, where a point is clearly better, fit again
  // from there; up to this many times (0: never).
  int probe_rounds = 2;
  OptimumProbeOptions probe;
  std::vector<std::string> profile_also;  // qualified names profiled even when not loose
  ProfileOptions profile;
};

struct StiffnessEstimate {
  std::string parameter;
  BisectionResult result;
};

struct FitReport {
  ModelParams start;
  LevellingEstimate levelling;
  std::vector<StiffnessEstimate> stiffnesses;
  ModelParams initial;  // after levelling, Algorithm 1 and the refit on the bare captures
  double bare_rmse_mm = 0.0;  // of that refit (0 if not run)
  LeastSquaresResult joint;
  // Each time the probe restarted the joint fit: where from, e.g. "the
  // least squares restarted from mass_kg 0.51977 -> 0.52016 (...)".
  std::vector<std::string> probe_notes;
};

// Stage ("levelling", "algorithm 1: spring_k", "least squares"), progress.
using FitProgress = std::function<void(const std::string& stage, int done, int total, const std::string& detail)>;

// The progress detail of a least-squares iteration, "RMSE 1.234 mm", and the
// RMSE read back from one (nullopt for any other detail), so a relay of the
// progress (the server) can report it as a number.
std::string rmse_detail(double rmse_mm);
std::optional<double> rmse_of_detail(const std::string& detail);
// A least-squares fit's iterations reported to `progress` as `stage`, each
// with its RMSE (rmse_detail).
LeastSquaresProgress least_squares_progress(const FitProgress& progress, const std::string& stage);

// A converged least-squares fit may sit beside a clearly better basin
// (optimum_probe.h), and one stopped at its iteration cap may still be far
// up a valley: fits again from the best probed point while one is, up to
// options.probe_rounds times, and says where from in `notes`.
LeastSquaresResult probe_and_refit(const Dataset& dataset, const std::vector<FitParameter>& parameters,
                                   const FitOptions& options, const FitProgress& progress, LeastSquaresResult fit,
                                   std::vector<std::string>& notes);

// Fits the baseline plus `effects` (switched on with their defaults unless
// `start` has values for them).
FitReport fit_model(const Dataset& dataset, const ModelParams& start, const std::vector<std::string>& effects,
                    const FitOptions& options, const FitProgress& progress = {});

}  // namespace hj
