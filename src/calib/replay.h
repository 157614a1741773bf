// Replays a measurement session's steps in the simulator and predicts each
// capture: the settled surface rasterised onto the session's sample grid
// (docs/model.md, "Measured surfaces"), as changed by any measurement
// effect (Effect::adjust_measurement, e.g. sensor_tilt).
#pragma once

#include <Eigen/Core>
#include <functional>
#include <string>
#include <vector>

#include "calib/session.h"
#include "sim/simulator.h"

namespace hj {

struct PredictedCapture {
  int step_index = 0;        // position in the session's "steps"
  std::string frame;         // relative frame path, as in the session
  std::string label;
  Eigen::MatrixXd heights_mm;  // (ny x nx), NaN where no triangle covers
};

// Called after each step: steps done, steps in all, and the step's report.
using ReplayProgress = std::function<void(int done, int total, const SessionStep& step, const SettleReport& settle)>;

// The settled positions (3 x N, m) after each step of a replay, by step
// (empty for a capture): recorded by one replay, they warm-start another of
// the same session under nearby parameters (Simulator::apply with a start:
// the other replay's state moved as this one moved over the step).
using ReplayTrace = std::vector<Eigen::Matrix3Xd>;

// Session s's trace among `traces` (one per session), or nullptr where there
// is none to start from (no traces, too few, or an empty one).
inline const ReplayTrace* session_trace(const std::vector<ReplayTrace>* traces, int s) {
  return traces && s < static_cast<int>(traces->size()) && !(*traces)[s].empty() ? &(*traces)[s] : nullptr;
}

// The sample grid's positions in the device frame (mm), x (nx) and y (ny),
// as Effect::adjust_measurement takes them.
Eigen::VectorXd sample_x_mm(const SessionGrid& grid);
Eigen::VectorXd sample_y_mm(const SessionGrid& grid);

// Called with each capture as the replay makes it; an exception it throws
// stops the replay and goes to replay_session's caller.
using CaptureSink = std::function<void(const PredictedCapture& capture)>;

// The session's device with `params` (whose max pressure is replaced by the
// session's). Throws SessionError naming the step when an action fails.
std::vector<PredictedCapture> replay_session(const Session& session, int segments, SurfaceParameters params,
                                             const SimulatorOptions& options, const ReplayProgress& progress = {},
                                             const ReplayTrace* warm_start = nullptr, ReplayTrace* trace = nullptr,
                                             const CaptureSink& on_capture = {});

}  // namespace hj
