// One run of a step control of the static solver (static_solver.h): the
// pseudo-transient continuation (K + mu I) dx = F from state.x, the shift mu
// following the control, with the stability check and the pushes off saddles.
#pragma once

#include <vector>

#include "model/device_state.h"
#include "sim/force_model.h"
#include "sim/settle_report.h"
#include "sim/shifted_solver.h"
#include "sim/static_solver.h"
#include "sim/step_system.h"
#include "sim/stiffness_matrix.h"

namespace hj {

// How the shift mu follows the iterations.
enum class StepControl {
  // mu shrinks 3x per step while steps stay under the cap, grows to keep
  // them there: an implicit overdamped flow at a fixed displacement per step
  // ending as Newton. Fast where the linear model holds over a step.
  kDisplacement,
  // mu shrinks only while the linear model predicts the new residual well
  // (rho below), and grows when it fails: slower, but it holds on stiff
  // jammed cells whose rotation the linear model gets wrong.
  kModelTrust,
};

// Iterates from state.x; returns with report.converged set when a stable
// equilibrium (or max_restarts pushes) is reached within max_iterations.
// The steps are solved in `system`'s DOFs. Over a mirror subspace only the
// fast control runs, without the stability check, which must see every DOF
// (k): the careful controls' model tests are written for the full system.
void run_continuation(const ForceModel& model, DeviceState& state, StiffnessMatrix& k, StepSystem& system,
                      ShiftedSolver& solver, const std::vector<char>& fixed, const StaticSolverOptions& options,
                      StepControl control, int max_iterations, double mu0, SettleMemory& memory,
                      SettleReport& report);

}  // namespace hj
