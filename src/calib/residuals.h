// Model versus measurement: each capture of a dataset predicted by replaying
// its session (replay.h) and compared with the measured frame, sample by
// sample. Missing samples (NaN in the frame) and samples no triangle of the
// predicted surface covers are not compared. Sessions run in parallel.
#pragma once

#include <Eigen/Core>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "calib/dataset.h"
#include "calib/model_params.h"
#include "calib/replay.h"
#include "calib/replay_tally.h"

namespace hj {

struct ReplayOptions {
  int segments = 4;  // p, mesh segments per cell edge
  StaticSolverOptions solver;
  int threads = 0;   // 0: one per core
  // Explicit steps a failed static settle may fall back to. A fit probes
  // parameters where the model has no equilibrium (the net creases just
  // below levelling), and must learn that quickly; see fitting_replay().
  long fallback_max_steps = 2'000'000;
  // False: a settle the static solver cannot finish fails at once, without
  // the implicit flow and explicit fallbacks (a coarse scan that only
  // looks for a good start, effect_scan.h, and steps over such points).
  bool fallbacks = true;
  // Polled while settling (SimulatorOptions::interrupted): true stops the
  // replay, the fit or the diagnosis with SettleInterrupted, which the
  // library's fallbacks for failed replays let through. A server sets it
  // from its caller's cancellation and deadline.
  std::function<bool()> interrupted;
  // If set, every session replay is counted there (not owned; thread-safe).
  ReplayTally* tally = nullptr;
};

// True when options.interrupted is set and says so.
bool is_interrupted(const ReplayOptions& options);
// Throws SettleInterrupted when is_interrupted(options).
void throw_if_interrupted(const ReplayOptions& options);

// The options of fits: a short explicit fallback.
ReplayOptions fitting_replay(ReplayOptions options);

// The error of one capture, residual = predicted - measured.
struct CaptureError {
  int samples = 0;             // compared
  int uncovered = 0;           // measured, but not covered by the prediction
  int within_accuracy = 0;     // |residual| <= the sensor's accuracy
  double sum_sq_mm2 = 0.0;
  double sum_abs_mm = 0.0;
  double max_mm = 0.0;         // largest |residual|
  double mean_mm = 0.0;        // mean signed residual
  Eigen::MatrixXd residual_mm;  // (ny x nx), NaN where not compared

  double rmse_mm() const;
  double mae_mm() const;
  double share_within_accuracy() const;
};

CaptureError compare_capture(const Eigen::MatrixXd& predicted_mm, const Eigen::MatrixXd& measured_mm,
                             double accuracy_mm);

// The cell (r, c) whose footprint holds sample (ix, iy), or false if the
// sample lies outside the array. Samples on a shared border go to the cell
// of higher index, those on the far edge to the last cell.
bool cell_of_sample(const Session& session, int ix, int iy, int& r, int& c);

struct SessionEvaluation {
  std::string name;
  std::vector<PredictedCapture> predicted;
  std::vector<CaptureError> captures;  // parallel to MeasuredSession::captures
};

struct Evaluation {
  std::vector<SessionEvaluation> sessions;  // parallel to Dataset::sessions
  long samples = 0;
  double sum_sq_mm2 = 0.0;
  double sum_abs_mm = 0.0;
  Eigen::MatrixXd cell_sum_sq_mm2;  // (R x C)
  Eigen::MatrixXd cell_samples;     // (R x C)

  double rmse_mm() const;
  double mae_mm() const;
  Eigen::MatrixXd cell_rmse_mm() const;  // (R x C), NaN for a cell without samples
};

// Called as each session finishes: sessions done, in all, and its name.
using EvaluationProgress = std::function<void(int done, int total, const std::string& session)>;

// The parameters' simulator options (their effects switched on).
SimulatorOptions simulator_options(const ModelParams& params, const ReplayOptions& options);

// Replays every session with `params` and compares every capture.
// @throws SessionError naming the session and step whose action fails.
// warm_start / traces: one ReplayTrace per session (see replay.h).
Evaluation evaluate_dataset(const Dataset& dataset, const ModelParams& params, const ReplayOptions& options,
                            const EvaluationProgress& progress = {}, const std::vector<ReplayTrace>* warm_start = nullptr,
                            std::vector<ReplayTrace>* traces = nullptr);

// The least-squares residuals of one session: predicted - measured in mm at
// every sample the camera saw, capture by capture, row by row
// (residual_count entries, so that the layout depends on the measurement
// only). Where the predicted surface does not cover a sample, it is
// predicted at the clamp level, 0 mm (the rig's frame around the
// membrane), not counted as a perfect fit: otherwise a model that pulls
// its rim in a little (boundary_compliance) uncovers the rim samples and
// lowers its cost by their noise, and diagnose chose it on data without it.
// warm_start / trace: as replay_session's (replay.h).
Eigen::VectorXd session_residuals(const MeasuredSession& session, const ModelParams& params,
                                  const ReplayOptions& options, const ReplayTrace* warm_start = nullptr,
                                  ReplayTrace* trace = nullptr);
int residual_count(const MeasuredSession& session);
// The same residuals from captures already predicted (one per capture of
// the session, in order).
Eigen::VectorXd capture_residuals(const MeasuredSession& session, const std::vector<PredictedCapture>& predicted);

// The sum of squares of every session's residuals at params, the sessions
// replayed one after another (for callers that run several points in
// parallel: effect_scan.h, optimum_probe.h); infinity where a session has
// no equilibrium. SettleInterrupted is let through.
// With session_threads > 1 the sessions run on that many threads, for a
// caller with fewer points than cores.
// With a bound, the caller needs the sum only where it is at most the
// bound: once the captures so far pass it, the replays stop and a value
// above the bound (the sum so far) is returned. A session with no
// equilibrium after that point is not reached, so it does not make the
// sum infinite.
// With warm_start (a trace per session, empty for none), each session's
// settles start from those states (replay_session); with traces, each
// session's settled states are recorded there.
double dataset_sum_of_squares(const Dataset& dataset, const ModelParams& params, const ReplayOptions& options,
                              int session_threads = 1, double bound = std::numeric_limits<double>::infinity(),
                              const std::vector<ReplayTrace>* warm_start = nullptr,
                              std::vector<ReplayTrace>* traces = nullptr);

}  // namespace hj
