#include "calib/replay.h"

#include "calib/rasterize.h"

namespace hj {

Eigen::VectorXd sample_x_mm(const SessionGrid& grid) {
  return Eigen::VectorXd::LinSpaced(grid.nx, 0, grid.nx - 1) * grid.dx_mm + Eigen::VectorXd::Constant(grid.nx, grid.x0_mm);
}

Eigen::VectorXd sample_y_mm(const SessionGrid& grid) {
  return Eigen::VectorXd::LinSpaced(grid.ny, 0, grid.ny - 1) * grid.dy_mm + Eigen::VectorXd::Constant(grid.ny, grid.y0_mm);
}

// The start of a warm-started step: this replay's state moved as the warm
// replay's moved over the same step. Its own absolute positions were settled
// under other parameters, and jammed cells keep this replay's bend angles
// (phi_eq): under stiff jams they are far from equilibrium in force (demo
// jammed-sweep, k 1 % off, kappa_jam 100: 165 N), while the move is not.
// Written as warm_after plus the offset so that a replay still on the warm
// one's states (a parameter that does not move them) starts exactly there.
static Eigen::Matrix3Xd warm_move(const Eigen::Matrix3Xd& now, const Eigen::Matrix3Xd& warm_before,
                                  const Eigen::Matrix3Xd& warm_after) {
  return warm_after + (now - warm_before);
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
  const Eigen::Matrix3Xd* warm_before = nullptr;  // the warm replay's state before this step
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
        const Eigen::Matrix3Xd* warm = warm_start ? &(*warm_start)[i] : nullptr;
        if (warm && warm->cols() != sim.state().x.cols()) warm = nullptr;
        if (warm) sim.apply(step.action, warm_before ? warm_move(sim.state().x, *warm_before, *warm) : *warm);
        else sim.apply(step.action);
        warm_before = warm;
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
