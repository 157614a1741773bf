#include "sim/static_solver.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>

#include "sim/continuation.h"
#include "sim/mirror_symmetry.h"
#include "sim/process_tuning.h"
#include "sim/shifted_solver.h"
#include "sim/step_system.h"
#include "sim/stiffness_matrix.h"

namespace hj {

void StaticSolverOptions::validate() const {
  auto bad = [](const char* field, const std::string& why) {
    throw std::invalid_argument(std::string("static solver option ") + field + " " + why);
  };
  if (!(force_tolerance_n > 0.0) || !std::isfinite(force_tolerance_n)) bad("force_tolerance_n", "(N) must be > 0");
  if (max_iterations < 1) bad("max_iterations", "must be at least 1");
  if (fast_iterations < 0) bad("fast_iterations", "must be >= 0");
  if (!(initial_shift >= 0.0) || !std::isfinite(initial_shift)) bad("initial_shift", "(x spring_k) must be >= 0");
  if (!(max_step_fraction > 0.0)) bad("max_step_fraction", "(x h) must be > 0");
  if (!(fast_step_fraction > 0.0)) bad("fast_step_fraction", "(x h) must be > 0");
  if (max_restarts < 0) bad("max_restarts", "must be >= 0");
  if (push_iterations < 1) bad("push_iterations", "must be at least 1");
  if (stall_iterations < 1) bad("stall_iterations", "must be at least 1");
}

namespace {

using Clock = std::chrono::steady_clock;

// The fast control on the displacements that keep the state's mirror
// symmetry (mirror_symmetry.h), if it has one: its equilibrium is one of
// the full system, whose stability the full settle then checks. state.x is
// left there if it converged, as it was otherwise; report counts the steps.
// From a symmetric state the fast control's steps on all DOFs are the same
// steps (K and F keep the symmetry, and the residual norms are weighted to
// match), so where this one fails that one would too, and is not run.
enum class SymmetricSettle { kNotTried, kSettled, kFailed };
SymmetricSettle settle_mirror_symmetric(const ForceModel& model, DeviceState& state, StiffnessMatrix& k,
                                        const std::vector<char>& fixed, const StaticSolverOptions& options,
                                        double mu0, SettleReport& report) {
  const MirrorGroup group = mirror_symmetry_of(model, state);
  if (group.trivial()) return SymmetricSettle::kNotTried;
  // A start already at equilibrium stays exactly where it is: averaging it
  // would move it by rounding (a repeated action, a warm replay whose
  // parameter moves nothing). Asked only of symmetric states, so that an
  // asymmetric one pays no force evaluation more than the full settle's.
  Eigen::Matrix3Xd f;
  model.forces(state, state.x, f);
  if (max_free_force(f, fixed) < options.force_tolerance_n) return SymmetricSettle::kNotTried;
  const Eigen::Matrix3Xd start_x = state.x;
  state.x = mirror_average(model.mesh(), state.x, group, fixed);
  const MirrorSubspace subspace(model.mesh(), k, group);
  StepSystem system(k, subspace);
  ShiftedSolver solver;
  StaticSolverOptions symmetric = options;
  symmetric.check_stability = false;
  SettleMemory unused;
  SettleReport tried;
  run_continuation(model, state, k, system, solver, fixed, symmetric, StepControl::kDisplacement,
                   options.fast_iterations, mu0, unused, tried);
  report.iterations += tried.iterations;
  report.residual_n = tried.residual_n;
  if (tried.converged) return SymmetricSettle::kSettled;
  state.x = start_x;
  return SymmetricSettle::kFailed;
}

}  // namespace

SettleReport settle_static(const ForceModel& model, DeviceState& state, const StaticSolverOptions& options,
                           SettleMemory* memory) {
  SettleMemory scratch;
  SettleMemory& remembered = memory ? *memory : scratch;
  options.validate();
  const auto start = Clock::now();
  const Mesh& mesh = model.mesh();
  const std::vector<char> fixed = model.fixed_points(state);
  StiffnessMatrix k(mesh, fixed, [&](StiffnessSink& sink) { model.add_stiffness(state, state.x, sink); });
  SettleReport report;
  if (k.num_dofs() == 0) {
    report.converged = true;
    return report;
  }
  tune_process_for_settling();
  const double mu0 = options.initial_shift * model.params().spring_k;
  const Eigen::Matrix3Xd start_x = state.x;
  // The fast control first, within a small budget (on the symmetric
  // displacements where the state has a mirror symmetry); where it does
  // not settle, the careful one from the same start.
  const bool fast_failed = options.mirror_symmetry && options.fast_iterations > 0 &&
                           settle_mirror_symmetric(model, state, k, fixed, options, mu0, report) ==
                               SymmetricSettle::kFailed;
  StepSystem system(k);
  ShiftedSolver solver;
  if (options.fast_iterations > 0 && !fast_failed) {
    run_continuation(model, state, k, system, solver, fixed, options, StepControl::kDisplacement,
                     options.fast_iterations, mu0, remembered, report);
    if (!report.converged) {
      state.x = start_x;
      report.restarts = 0;
    }
  }
  if (!report.converged && !options.careful) {
    report.seconds = std::chrono::duration<double>(Clock::now() - start).count();
    return report;
  }
  if (!report.converged)
    run_continuation(model, state, k, system, solver, fixed, options, StepControl::kModelTrust, options.max_iterations,
                     mu0, remembered, report);
  report.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  return report;
}

}  // namespace hj
