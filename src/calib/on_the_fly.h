// Calibration on the fly (docs/render.md, correction "model"): captures of
// one device (a render's probe: the free membrane at a few pressures, or
// runs from rest, a plan's actions then a capture) form a measurement
// dataset; the device model is fitted on it, with the optional effects a
// small selection adds: each candidate is tried alone on top of the current
// model, and those significant by diagnose's rule (delta BIC and an
// in-sample gain; not its cross-validation: a probe is one session) are
// added together and fitted jointly. A planner then plans with the fitted
// model.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "calib/dataset.h"
#include "calib/least_squares.h"

namespace hj {

// A frame ((grid.ny x grid.nx) mm, NaN = not seen) and how many of a
// run's actions came before it.
struct RunCapture {
  size_t after_actions = 0;
  Eigen::MatrixXd frame_mm;
};

// A run from rest as a session: `actions` in order, each capture after its
// share of them (in order).
// @throws std::invalid_argument naming the run if a frame's shape is not
//         the grid's or the captures are out of order or past the actions.
MeasuredSession captured_session(const std::string& name, const SessionDevice& device, const SessionGrid& grid,
                                 const std::vector<Action>& actions, const std::vector<RunCapture>& captures);

// One run from rest: `actions`, then a capture of `frame_mm`.
MeasuredSession run_session(const std::string& name, const SessionDevice& device, const SessionGrid& grid,
                            const std::vector<Action>& actions, const Eigen::MatrixXd& frame_mm);

struct OnTheFlyOptions {
  // The baseline's parameters that are fitted (SurfaceParameters fields);
  // the others keep the start's values.
  std::vector<std::string> surface_parameters = {"spring_k"};
  // Optional effects the selection may add, tried in this order on top of
  // the current model; one the start already has is refitted, not tried.
  std::vector<std::string> candidates = {"sensor_tilt", "stiffening", "cell_stiffness"};
  // Parameters of those effects held at the start's value (qualified
  // names). A stiffness gradient domes one side higher, as a camera tilt
  // seems to: on two captures of a tilted camera the fit traded them
  // (tilt_x 13.0 against the true 15 mrad, grad_x -0.10 on a device without
  // one), so only cell_stiffness' bulge (a soft or stiff middle) is fitted.
  std::vector<std::string> held = {"cell_stiffness.grad_x", "cell_stiffness.grad_y"};
  int max_iterations = 5;    // Levenberg-Marquardt iterations of the model's fit
  int trial_iterations = 3;  // and of each candidate's trial
  // Where a candidate's parameters are scanned before its trial (shares of
  // the way to each bound, effect_scan.h): coarser than diagnose's.
  std::vector<double> scan_fractions = {0.01, 0.1, 0.3, 0.7};
  // A candidate is added when its refit lowers BIC by more than
  // -max_delta_bic and the RMSE by at least min_fit_gain of the current's.
  double max_delta_bic = -10.0;
  double min_fit_gain = 0.005;
  ReplayOptions replay;  // segments: the planner's p; interrupted: the caller's cancel

  // @throws std::invalid_argument naming the field that is wrong.
  void validate() const;
};

struct OnTheFlyFit {
  ModelParams params;                        // the fitted model (the start's effects and those added)
  std::vector<std::string> added;            // effects added, in the order tried
  std::vector<ParameterEstimate> estimates;  // of every fitted parameter
  double rmse_mm = 0.0;
  long samples = 0;
  int captures = 0;
  int replays = 0;                 // whole-dataset replays: fits (values and Jacobian columns) and scans
  std::vector<std::string> notes;  // each candidate tried, its figures, and "added NAME"
};

// The fitted parameters of `params`: options.surface_parameters, then those
// of each of its effects that is a candidate, less options.held.
std::vector<FitParameter> on_the_fly_parameters(const ModelParams& params, const OnTheFlyOptions& options);

// Fits `start` (its candidate effects refitted), tries each candidate it
// lacks alone on top, and fits the model again with every significant one.
// @throws std::invalid_argument (bad options, a dataset without samples, an
//         unknown name), std::runtime_error if the start does not replay
//         the dataset; SettleInterrupted when options.replay.interrupted says so.
OnTheFlyFit calibrate_on_the_fly(const Dataset& dataset, const ModelParams& start, const OnTheFlyOptions& options);

}  // namespace hj
