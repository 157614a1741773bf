#include "calib/replay.h"

#include "calib/rasterize.h"

namespace hj {

Eigen::VectorXd sample_x_mm(const SessionGrid& grid) {
  return Eigen::VectorXd::LinSpaced(grid.nx, 0, grid.nx - 1) * grid.dx_mm + Eigen::VectorXd::Constant(grid.nx, grid.x0_mm);
}

Eigen::VectorXd sample_y_mm(const SessionGrid& grid) {
  return Eigen::VectorXd::LinSpaced(grid.ny, 0, grid.ny - 1) * grid.dy_mm + Eigen::VectorXd::Constant(grid.ny, grid.y0_mm);
}

std::vector<PredictedCapture> replay_session(const Session& session, int segments, SurfaceParameters params,
                                             const SimulatorOptions& options, const ReplayProgress& progress,
                                             const ReplayTrace* warm_start, ReplayTrace* trace,
                                             const CaptureSink& on_capture) {
  params.max_pressure_pa = session.device.max_pressure_kpa * 1000.0;
  Simulator sim(session.device.geometry(segments), params, options);
  const Eigen::VectorXd x_mm = sample_x_mm(session.grid), y_mm = sample_y_mm(session.grid);
  std::vector<PredictedCapture> captures;
  const int total = static_cast<int>(session.steps.size());
  if (warm_start && static_cast<int>(warm_start->size()) != total)
    throw std::invalid_argument("replay_session: the warm start has " + std::to_string(warm_start->size()) +
                                " steps, " + session.name + " " + std::to_string(total));
  if (trace) trace->assign(total, Eigen::Matrix3Xd());
  for (int i = 0; i < total; ++i) {
    const SessionStep& step = session.steps[i];
    if (step.kind == SessionStep::Kind::kCapture) {
      Eigen::MatrixXd heights = rasterize_top_view(sim.mesh(), sim.state().x, session.grid);
      // Measurement effects (a tilted camera) change what the camera reports.
      sim.model().adjust_measurement(x_mm, y_mm, heights);
      captures.push_back({step.index, step.frame, step.label, std::move(heights)});
      if (on_capture) on_capture(captures.back());
    } else {
      try {
        const Eigen::Matrix3Xd* start = warm_start ? &(*warm_start)[i] : nullptr;
        if (start && start->cols() == sim.state().x.cols()) sim.apply(step.action, *start);
        else sim.apply(step.action);
        if (trace) (*trace)[i] = sim.state().x;
      } catch (const SettleInterrupted&) {
        throw;  // the caller stopped the work: not a failed replay
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
