// A settle that follows a snap-through to the next stable equilibrium: the
// overdamped flow c dx/dt = F(x) integrated with backward Euler,
//   mu (x_{n+1} - x_n) = F(x_{n+1}),   mu = c / dt,
// each step solved by Newton on (K + mu I) dx = F - mu (x - x_n) with the
// exact sparse stiffness K = -dF/dx, dt growing while Newton converges in
// few iterations and shrinking when it does not. Unlike the static solver's
// single regularised Newton step per iteration, judged on whether its
// linear model predicts the new residual, a step here is judged only on
// whether it solves its own implicit equation: the flow may carry the
// residual up (over the ridge where a jammed sag's equilibrium disappears)
// on its way to the next equilibrium. It ends once the residual is small;
// settle_static then polishes it and checks its stability
// (Simulator::settle_once).
#pragma once

#include <functional>

#include "model/device_state.h"
#include "sim/force_model.h"
#include "sim/settle_report.h"

namespace hj {

struct ImplicitFlowOptions {
  // The flow ends when the largest |F| on a free point falls below this.
  double force_tolerance_n = 1e-7;
  int max_steps = 400;                 // backward Euler steps (4 x 6 snap: 65)
  int newton_iterations = 6;           // per step, before dt is cut
  double initial_shift = 1.0;          // mu at the start, in units of spring_k
  double max_step_fraction = 0.5;      // largest move of a point per step, in h
  // Polled every step; true throws SettleInterrupted (state left mid-way).
  std::function<bool()> interrupted;
  // Asked of the positions and the largest |F| on a free point (N) after
  // every accepted step; true ends the flow there, unconverged (a planner
  // stops at a dead end, sim/dead_end_watch.h).
  std::function<bool(const Eigen::Matrix3Xd& x, double residual_n)> abandon;

  // Throws std::invalid_argument naming the bad field.
  void validate() const;
};

// Flows state.x in place from where it is. Never throws on a hard case:
// returns converged = false (max_steps spent, or dt cut to nothing),
// leaving the state where the flow got to.
SettleReport settle_implicit_flow(const ForceModel& model, DeviceState& state, const ImplicitFlowOptions& options = {});

}  // namespace hj
