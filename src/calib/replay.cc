#include "calib/replay.h"

#include "calib/rasterize.h"

namespace hj {

std::vector<PredictedCapture> replay_session(const Session& session, int segments, SurfaceParameters params,
                                             const SimulatorOptions& options, const ReplayProgress& progress) {
  params.max_pressure_pa = session.device.max_pressure_kpa * 1000.0;
  Simulator sim(session.device.geometry(segments), params, options);
  std::vector<PredictedCapture> captures;
  const int total = static_cast<int>(session.steps.size());
  for (int i = 0; i < total; ++i) {
    const SessionStep& step = session.steps[i];
    if (step.kind == SessionStep::Kind::kCapture) {
      captures.push_back({step.index, step.frame, step.label, rasterize_top_view(sim.mesh(), sim.state().x, session.grid)});
    } else {
      try {
        sim.apply(step.action);
      } catch (const std::exception& e) {
        throw SessionError(session.name + ": steps[" + std::to_string(step.index) + "] (" + step.action.op_name() +
                           "): " + e.what());
      }
    }
    if (progress) progress(i + 1, total, step, sim.last_settle());
  }
  return captures;
}

}  // namespace hj
