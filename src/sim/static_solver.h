// Static equilibrium by pseudo-transient continuation: Newton steps on the
// force residual, each regularised as an implicit step of the overdamped
// flow c dx/dt = F(x),
//   (K + mu I) dx = F,   K = -dF/dx (analytic, sparse), mu = c / dt,
// so it starts as a heavily damped relaxation from the previous state and
// ends as Newton. mu follows one of two controls (continuation.cc): a fast
// one that keeps each move near the cap, tried first (and given up once its
// residual runs away), and a careful one that shrinks mu only while the
// linear model predicts the residual, judged in the compliance-weighted
// norm |(K + mu I)^-1 r| so the stiff springs of jammed cells do not veto
// every step. Where neither settles, the settle reports converged = false
// and the simulator's fallbacks take over (simulator.h: the implicit flow,
// then explicit Euler). A converged
// state along which K diverges (divergence_mode.h: a saddle, or the creased
// net near levelling) is pushed along that mode and settled again; a push
// that reaches no other equilibrium within push_iterations goes back, and
// the settle ends there, reported marginal.
#pragma once

#include <functional>

#include "model/device_state.h"
#include "sim/force_model.h"
#include "sim/settle_report.h"

namespace hj {

struct StaticSolverOptions {
  double force_tolerance_n = 1e-9;   // largest |F| on a free point at the end
  int max_iterations = 1000;         // for the careful step control
  int fast_iterations = 40;          // budget of the fast one, tried first (0: skip)
  double initial_shift = 0.1;        // mu at the start, in units of spring_k
  double max_step_fraction = 1.0;    // largest move of a point per step, in h
  // The same for the fast control: it is abandoned when it fails, so it can
  // stride further (9 x 12 from a mirrored start: 24 steps at 2 h, 75 at 1 h).
  double fast_step_fraction = 2.0;
  int max_restarts = 6;              // pushes off unstable equilibria
  // Iterations a push may take to reach another equilibrium; past them the
  // settle ends on the one it left, reported marginal (a slowly diverging
  // mode, e.g. the shear mechanisms of a large dome, see unstable_mode).
  int push_iterations = 20;
  // The careful controls give up after this many iterations in which the
  // residual has not halved: there is nothing to converge to (the model
  // has no equilibrium there, e.g. a fold), and the remaining budget would
  // only make the failure slow. Set well above the longest such stretch of
  // a settle that converges.
  int stall_iterations = 500;
  bool check_stability = true;
  // Settle a mirror-symmetric state (mirror_symmetry.h: a free net under
  // uniform pressure, a symmetric pattern of jams and pins) on its symmetric
  // displacements first, a quarter or half of the unknowns, then check the
  // equilibrium's stability over all of them. Only on meshes of 1,000 free
  // DOFs or more.
  bool mirror_symmetry = true;
  // false: give up when the fast control does not settle, without the
  // careful ones (the simulator then tries the implicit flow first).
  bool careful = true;
  // Polled every step; true throws SettleInterrupted (state left mid-way).
  std::function<bool()> interrupted;

  // Throws std::invalid_argument naming the bad field.
  void validate() const;
};

// What one settle leaves for the next on the same device: the divergence
// mode last pushed along without reaching another equilibrium. The next
// settle does not push along the same mode again (a large dome's slow shear
// mode otherwise costs push_iterations at every action on it).
struct SettleMemory {
  Eigen::VectorXd marginal_mode;  // unit, over the free DOFs of that settle
};

// Settles state.x in place from where it is. Never throws on a hard case:
// returns converged = false, leaving the best state found.
SettleReport settle_static(const ForceModel& model, DeviceState& state, const StaticSolverOptions& options = {},
                           SettleMemory* memory = nullptr);

}  // namespace hj
