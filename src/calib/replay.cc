#include "calib/replay.h"

#include "calib/rasterize.h"

namespace hj {

std::vector<PredictedCapture> replay_session(const Session& session, int segments, SurfaceParameters params,
                                             const SimulatorOptions& options, const ReplayProgress& progress) {
  params.max_pressure_pa = session.device.max_pressure_kpa * 1000.0;
  Simulator sim(session.device.geometry(segments), params, options);
  const Eigen::VectorXd x_mm = Eigen::VectorXd::LinSpaced(session.grid.nx, 0, session.grid.nx - 1) * session.grid.dx_mm +
                               Eigen::VectorXd::Constant(session.grid.nx, session.grid.x0_mm);
  const Eigen::VectorXd y_mm = Eigen::VectorXd::LinSpaced(session.grid.ny, 0, session.grid.ny - 1) * session.grid.dy_mm +
                               Eigen::VectorXd::Constant(session.grid.ny, session.grid.y0_mm);
  std::vector<PredictedCapture> captures;
  const int total = static_cast<int>(session.steps.size());
  for (int i = 0; i < total; ++i) {
    const SessionStep& step = session.steps[i];
    if (step.kind == SessionStep::Kind::kCapture) {
      Eigen::MatrixXd heights = rasterize_top_view(sim.mesh(), sim.state().x, session.grid);
      // Measurement effects (a tilted camera) change what the camera reports.
      sim.model().adjust_measurement(x_mm, y_mm, heights);
      captures.push_back({step.index, step.frame, step.label, std::move(heights)});
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
