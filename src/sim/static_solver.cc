#include "sim/static_solver.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>

#include "sim/divergence_mode.h"
#include "sim/mirror_symmetry.h"
#include "sim/process_tuning.h"
#include "sim/shifted_solver.h"
#include "sim/step_system.h"
#include "sim/symmetric_stability.h"
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

// The fast control gives up once a trial residual exceeds this multiple of
// the one it started from (3 x 4, all jammed, 295 -> 0 Pa: it otherwise
// spends its 40 steps reaching 1e4 times the start).
constexpr double kAbandonGrowth = 100.0;
// Refused careful steps after which the control remembers the shifts it
// refused (see run_continuation).
constexpr int kRefusalsBeforeMemory = 50;
// Free DOFs from which a settle first tries the symmetric displacements
// alone: the paper's 3 x 4 array (495) settles in a few milliseconds
// without them, and its fits keep their rounding.
constexpr int kMinMirrorDofs = 1000;
// Refused fast steps after which a push off a saddle is given up. Leaving a
// saddle raises the residual, and the fast control refuses a step whose
// residual grows tenfold and starts its shift again from mu0: each refusal
// is the step out, not taken (it comes when mu falls to about |lambda| of
// the pushed mode), and the push then creeps at 1.2-1.5 x its amplitude a
// cycle. Over the test suite the 25 fast pushes that reached no other
// equilibrium within push_iterations were all refused at least twice (the
// second 4-12 steps after the push, not 21), and the 11 that reached one
// (in 8-15 steps) at most once; the outcome is the same, only sooner.
constexpr int kPushRefusals = 2;

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
  // kModelTrust with each step bent by its geodesic acceleration: the
  // rescue where the careful control does not settle.
  kCurvedModelTrust,
};

// Bends the step v along the curve the forces follow (geodesic
// acceleration, Transtrum & Sethna 2012): F'' along v from one probe at
// h v, a = (K + mu I)^-1 F'', step v + a / 2. Jammed cells are ~1000 times
// stiffer in bending than the net is in stretch, so a straight step along a
// soft direction that turns a jammed cell loads its springs at second order
// and the linear model fails even for 0.01 mm steps (the creased sag of a
// 6 x 8 array with 12 jammed cells at 0.96 of levelling: no convergence in
// 1000 steps; with this, 434). Skipped where the correction is not small.
void add_geodesic_acceleration(const ForceModel& model, const DeviceState& state, const StepSystem& system,
                               ShiftedSolver& solver, double mu, const Eigen::VectorXd& residual,
                               Eigen::VectorXd& step) {
  constexpr double kProbe = 0.1, kMaxRatio = 0.75;
  Eigen::Matrix3Xd f_probe;
  model.forces(state, state.x + system.scatter(kProbe * step), f_probe);
  // F(x + h v) = F - h K v + h^2 F''/2, and K v = F - mu v.
  const Eigen::VectorXd second =
      (2.0 / (kProbe * kProbe)) * (system.gather(f_probe) - residual + kProbe * (residual - mu * step));
  Eigen::VectorXd accel;
  if (!solver.solve_again(system.matrix(), mu, second, accel) || !accel.allFinite()) return;
  if (2.0 * accel.norm() <= kMaxRatio * step.norm()) step += 0.5 * accel;
}

// Iterates from state.x; returns with report.converged set when a stable
// equilibrium (or max_restarts pushes) is reached within max_iterations.
// The steps are solved in `system`'s DOFs. Over a mirror subspace only the
// fast control runs, without the stability check, which must see every DOF
// (k): the careful controls' model tests are written for the full system.
void run_continuation(const ForceModel& model, DeviceState& state, StiffnessMatrix& k, StepSystem& system,
                      ShiftedSolver& solver, const std::vector<char>& fixed, const StaticSolverOptions& options,
                      StepControl control, int max_iterations, double mu0, SettleMemory& memory,
                      SettleReport& report) {
  if (system.num_dofs() != k.num_dofs() && (control != StepControl::kDisplacement || options.check_stability))
    throw std::logic_error("run_continuation: a subspace settle is the fast control without the stability check");
  // The system the steps are solved in: `system`, or after the fast
  // control's push off a mirror-symmetric equilibrium, the displacements
  // that keep the part of the symmetry the pushed mode keeps (the 9 x 12
  // dome's shear mode is odd under one mirror: half the unknowns).
  StepSystem* active = &system;
  ShiftedSolver* active_solver = &solver;
  std::unique_ptr<MirrorSubspace> push_subspace;
  std::unique_ptr<StepSystem> push_system;
  std::unique_ptr<ShiftedSolver> push_solver;
  const Mesh& mesh = model.mesh();
  const double max_step =
      (control == StepControl::kDisplacement ? options.fast_step_fraction : options.max_step_fraction) * mesh.spacing();
  Eigen::Matrix3Xd f, f_trial;
  model.forces(state, state.x, f);
  Eigen::VectorXd residual = system.gather(f);
  double mu = mu0;
  const double start_norm = system.force_norm(residual);
  double refused_mu = 0.0;  // the largest shift the careful control refused
  int refusals = 0;
  // The equilibrium last pushed off, and the iteration of the push.
  Eigen::Matrix3Xd pushed_from;
  Eigen::VectorXd pushed_mode;
  int pushed_at = -1;
  int push_refusals = 0;  // fast steps refused since the push
  // The residual norm when it last halved, and that iteration (stall_iterations).
  double halved_norm = start_norm;
  int halved_at = 0;
  // Whether system holds K at state.x (kept for the steps after a refused
  // one, where only the shift changes).
  bool unshifted_current = false;
  // A push that has not led to another equilibrium within its budget was
  // along a mode too weak to matter: settle for the equilibrium it left.
  auto settle_for_pushed_from = [&] {
    state.x = pushed_from;
    memory.marginal_mode = pushed_mode;
    model.forces(state, state.x, f);
    report.residual_n = max_free_force(f, fixed);
    report.converged = report.marginal = true;
  };
  for (int it = 0; it < max_iterations; ++it, ++report.iterations) {
    if (options.interrupted && options.interrupted()) throw SettleInterrupted();
    if (pushed_at >= 0 && it - pushed_at > options.push_iterations) return settle_for_pushed_from();
    report.residual_n = max_free_force(f, fixed);
    if (report.residual_n < options.force_tolerance_n) {
      pushed_at = -1;
      if (!options.check_stability || report.restarts >= options.max_restarts) {
        report.converged = true;
        return;
      }
      k.set_zero();
      model.add_stiffness(state, state.x, k);
      // The mode a push has already shown to lead nowhere (its direction
      // barely turns from one action to the next on the same device), asked
      // about first: a few solves from it, not the full search (9 x 12 dome
      // at 2 kPa: 53 -> 19 ms on 2026-11-25's machine).
      constexpr double kSameMode = 0.9;
      DivergenceSearch search(k.matrix());
      // The state's mirror symmetry, found when a question needs it.
      std::optional<MirrorGroup> found_symmetry;
      auto symmetry = [&] {
        if (!found_symmetry)
          found_symmetry = options.mirror_symmetry && k.num_dofs() >= kMinMirrorDofs ? mirror_symmetry_of(model, state)
                                                                                      : MirrorGroup{};
        return *found_symmetry;
      };
      // At a mirror-symmetric state, asked of the mode's symmetry class only.
      const std::optional<bool> known_in_class =
          memory.marginal_mode.size() > 0
              ? still_has_in_mirror_class(mesh, k, symmetry(), memory.marginal_mode, kSameMode)
              : std::nullopt;
      if (known_in_class ? *known_in_class : search.still_has(memory.marginal_mode, kSameMode)) {
        report.converged = report.marginal = true;
        return;
      }
      const Eigen::VectorXd mode = search.mode();
      if (mode.size() == 0) {
        report.converged = true;
        return;
      }
      if (memory.marginal_mode.size() == mode.size() && std::abs(memory.marginal_mode.dot(mode)) > kSameMode) {
        report.converged = report.marginal = true;
        return;
      }
      // Push off the saddle by a small fraction of h and relax again.
      Eigen::Matrix3Xd push = k.scatter(mode);
      active = &system;
      active_solver = &solver;
      if (control == StepControl::kDisplacement && !symmetry().trivial()) {
        // The mode lies in one symmetry class (K keeps them apart): pushed
        // along its part there, the surface keeps the mirrors that class
        // keeps, and settles on their displacements.
        const MirrorClass mode_class = strongest_mirror_class(mesh, push, symmetry(), fixed);
        if (mode_class.norm > 0.999 * push.norm()) {
          push = mirror_projection(mesh, push, symmetry(), mode_class.odd, fixed);
          if (const MirrorGroup kept = mirror_kernel(symmetry(), mode_class.odd); !kept.trivial()) {
            push_subspace = std::make_unique<MirrorSubspace>(mesh, k, kept);
            push_system = std::make_unique<StepSystem>(k, *push_subspace);
            push_solver = std::make_unique<ShiftedSolver>();
            active = push_system.get();
            active_solver = push_solver.get();
          }
        }
      }
      Eigen::Index r = 0, c = 0;
      const double largest = push.cwiseAbs().maxCoeff(&r, &c);
      if (push(r, c) < 0) push = -push;  // a deterministic choice of side
      pushed_from = state.x;
      pushed_mode = mode;
      pushed_at = it;
      push_refusals = 0;
      state.x += (0.05 * mesh.spacing() / largest) * push;
      unshifted_current = false;
      model.forces(state, state.x, f);
      residual = active->gather(f);
      mu = mu0;
      ++report.restarts;
      halved_norm = active->force_norm(residual);
      halved_at = it;
      continue;
    }
    if (const double norm = active->force_norm(residual); norm < 0.5 * halved_norm) {
      halved_norm = norm;
      halved_at = it;
    } else if (control != StepControl::kDisplacement && pushed_at < 0 && it - halved_at > options.stall_iterations) {
      break;  // stalled: nothing to converge to
    }
    if (!unshifted_current) {
      active->assemble(model, state, state.x);
      unshifted_current = true;
    }
    active->set_shift(mu);
    Eigen::VectorXd full_step;
    const double largest = active_solver->solve(active->matrix(), mu, residual, full_step)
                               ? active->scatter(full_step).colwise().norm().maxCoeff()
                               : NAN;
    if (!std::isfinite(largest)) {
      mu = std::max(4.0 * mu, mu0);
      continue;
    }
    if (control == StepControl::kCurvedModelTrust)
      add_geodesic_acceleration(model, state, *active, *active_solver, mu, residual, full_step);
    const Eigen::Matrix3Xd move = active->scatter(full_step);
    const double scale = std::min(1.0, max_step / move.colwise().norm().maxCoeff());
    const Eigen::Matrix3Xd x_trial = state.x + scale * move;
    model.forces(state, x_trial, f_trial);
    const Eigen::VectorXd residual_trial = active->gather(f_trial);
    const double old_norm = active->force_norm(residual), new_norm = active->force_norm(residual_trial);
    if (control == StepControl::kDisplacement) {
      // Heading away (stiff jammed cells turned by straight strides): leave
      // it to the careful control rather than spend the budget.
      if (pushed_at < 0 && new_norm > kAbandonGrowth * start_norm) return;
      if (!(new_norm < 10.0 * old_norm)) {
        if (pushed_at >= 0 && ++push_refusals >= kPushRefusals) return settle_for_pushed_from();
        mu = std::max(4.0 * mu, mu0);
        continue;
      }
      mu = scale < 1.0 ? std::max(mu, 1e-6 * mu0) * std::min(10.0, 1.0 / scale) : 0.3 * mu;
    } else if (control == StepControl::kModelTrust) {
      // rho: the error of the linear model's predicted residual, F - K s dx
      // = (1 - s) F + s mu dx, measured in the compliance-weighted norm,
      // i.e. after (K + mu I)^-1 (two more solves with the same LU). In the
      // plain norm the stiff springs of jammed cells dominate it, and steps
      // whose error those springs take back at once were refused (3 x 4, all
      // jammed, 295 -> 0 Pa: 158 steps in the plain norm, 58 in this one).
      Eigen::VectorXd correction, compliance_step;
      const bool solved = active_solver->solve_again(active->matrix(), mu, residual_trial, correction) &&
                          active_solver->solve_again(active->matrix(), mu, full_step, compliance_step);
      const Eigen::VectorXd predicted = (1.0 - scale) * full_step + (scale * mu) * compliance_step;
      const double rho = solved ? (correction - predicted).norm() / std::max((full_step - predicted).norm(), 1e-300)
                                : INFINITY;
      if (!(rho <= 1.0)) {
        refused_mu = std::max(refused_mu, mu);
        ++refusals;
        mu = std::max(4.0 * mu, mu0);
        continue;
      }
      mu *= rho < 0.1 ? 0.1 : rho < 0.3 ? 0.3 : 0.7;
      // Once refusals pile up, not back below twice the shift last refused
      // (a bound that halves with each accepted step): the shift otherwise
      // can cycle between an accepted mu0 and a refused mu0 / 10 for good
      // (6 x 8 volcano plan, 35 cells jammed, 300 -> 350 Pa). Only then: in
      // settles that converge without it, it changes which of two nearby
      // equilibria some reach (the fit tests' held-out session).
      if (refusals > kRefusalsBeforeMemory) {
        mu = std::max(mu, 2.0 * refused_mu);
        refused_mu *= 0.5;
      }
    } else {
      // The same in the plain norm, for the curved steps (whose bend the
      // linear model does not include).
      const Eigen::VectorXd predicted = (1.0 - scale) * residual + (scale * mu) * full_step;
      const double rho = (residual_trial - predicted).norm() / std::max((residual - predicted).norm(), 1e-300);
      if (rho > 1.0 && !(new_norm < old_norm)) {
        mu = std::max(4.0 * mu, mu0);
        continue;
      }
      if (rho < 0.1)
        mu *= 0.1;
      else if (rho < 0.3)
        mu *= 0.3;
      else if (rho < 1.0 || new_norm < 0.9 * old_norm)
        mu *= 0.7;
    }
    state.x = x_trial;
    unshifted_current = false;
    f.swap(f_trial);
    residual = residual_trial;
    if (mu < 1e-10 * mu0) mu = 0.0;
  }
  if (pushed_at >= 0) return settle_for_pushed_from();
  report.residual_n = max_free_force(f, fixed);
}

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
                           k.num_dofs() >= kMinMirrorDofs &&
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
  // The curved steps change which of two nearby equilibria a settle finds
  // in some cases that settle without them, so they are the last resort,
  // not the default (measured on the fit tests' held-out sessions).
  if (!report.converged) {
    state.x = start_x;
    report.restarts = 0;
    run_continuation(model, state, k, system, solver, fixed, options, StepControl::kCurvedModelTrust,
                     options.max_iterations, mu0, remembered, report);
  }
  report.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  return report;
}

}  // namespace hj
