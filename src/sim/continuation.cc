#include "sim/continuation.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>
#include <stdexcept>

#include "sim/divergence_mode.h"
#include "sim/mirror_symmetry.h"
#include "sim/symmetric_stability.h"

namespace hj {

namespace {

// The fast control gives up once a trial residual exceeds this multiple of
// the one it started from: heading away, it would only spend its budget.
constexpr double kAbandonGrowth = 100.0;
// The fast control gives up once its residual has not halved in this many
// steps: where it converges it halves every step or two, and where there is
// no equilibrium near the start (a snap-through past a fold) it wanders
// with the residual going up and down, and the flow that follows does the
// work (9 x 12, a pinned jammed plate, 2 to 2.5 kPa: 40 steps spent).
constexpr int kFastStallIterations = 10;
// Refused careful steps after which the control remembers the shifts it
// refused (Continuation::judge_model_trust).
constexpr int kRefusalsBeforeMemory = 50;
// Refused fast steps after which a push off a saddle is given up. Leaving a
// saddle raises the residual, and each step the fast control refuses for
// that is the step out, not taken; a push refused twice only creeps on.
constexpr int kPushRefusals = 2;
// Overlap above which a divergence mode is the one already known.
constexpr double kSameMode = 0.9;

// run_continuation's loop and its state, each stage of a step in its own
// method.
class Continuation {
 public:
  Continuation(const ForceModel& model, DeviceState& state, StiffnessMatrix& k, StepSystem& system,
               ShiftedSolver& solver, const std::vector<char>& fixed, const StaticSolverOptions& options,
               StepControl control, double mu0, SettleMemory& memory, SettleReport& report);
  void run(int max_iterations);

 private:
  // A trial step from state.x: the solved step, its cap and where it leads.
  struct Trial {
    Eigen::VectorXd full_step;  // the solution of the step system, uncapped
    double scale = 1.0;         // the cap's factor on it
    Eigen::Matrix3Xd x;
    Eigen::VectorXd residual;
    double old_norm = 0.0, new_norm = 0.0;
  };
  // What a step control makes of a trial.
  enum class Verdict { kAccept, kRefuse, kStop };

  bool at_equilibrium(int it);  // true: the run ends here
  bool known_mode_remains(DivergenceSearch& search);
  void push_off(const Eigen::VectorXd& mode, int it);
  void keep_push_in_mirror_class(Eigen::Matrix3Xd& push);
  bool stalled(int it);
  bool take_step();  // true: the run ends here
  std::optional<Trial> trial_step();
  Verdict judge_displacement(const Trial& trial);
  Verdict judge_model_trust(const Trial& trial);
  void accept(Trial& trial);
  void settle_for_pushed_from();
  MirrorGroup symmetry();

  const ForceModel& model_;
  const Mesh& mesh_;
  DeviceState& state_;
  StiffnessMatrix& k_;
  StepSystem& system_;
  ShiftedSolver& solver_;
  const std::vector<char>& fixed_;
  const StaticSolverOptions& options_;
  const StepControl control_;
  const double mu0_;
  SettleMemory& memory_;
  SettleReport& report_;
  const double max_step_;
  // The system the steps are solved in: `system`, or after the fast
  // control's push off a mirror-symmetric equilibrium, the displacements
  // that keep the part of the symmetry the pushed mode keeps (the 9 x 12
  // dome's shear mode is odd under one mirror: half the unknowns).
  StepSystem* active_;
  ShiftedSolver* active_solver_;
  std::unique_ptr<MirrorSubspace> push_subspace_;
  std::unique_ptr<StepSystem> push_system_;
  std::unique_ptr<ShiftedSolver> push_solver_;
  Eigen::Matrix3Xd f_, f_trial_;
  Eigen::VectorXd residual_;
  double mu_;
  double start_norm_;
  double refused_mu_ = 0.0;  // the largest shift the careful control refused
  int refusals_ = 0;
  // The equilibrium last pushed off, and the iteration of the push.
  Eigen::Matrix3Xd pushed_from_;
  Eigen::VectorXd pushed_mode_;
  int pushed_at_ = -1;
  int push_refusals_ = 0;  // fast steps refused since the push
  // The residual norm when it last halved, and that iteration (stall_iterations).
  double halved_norm_;
  int halved_at_ = 0;
  // Whether the active system holds K at state.x (kept for the steps after
  // a refused one, where only the shift changes).
  bool unshifted_current_ = false;
  // The state's mirror symmetry, found when a stability question needs it.
  std::optional<MirrorGroup> found_symmetry_;
};

Continuation::Continuation(const ForceModel& model, DeviceState& state, StiffnessMatrix& k, StepSystem& system,
                           ShiftedSolver& solver, const std::vector<char>& fixed, const StaticSolverOptions& options,
                           StepControl control, double mu0, SettleMemory& memory, SettleReport& report)
    : model_(model),
      mesh_(model.mesh()),
      state_(state),
      k_(k),
      system_(system),
      solver_(solver),
      fixed_(fixed),
      options_(options),
      control_(control),
      mu0_(mu0),
      memory_(memory),
      report_(report),
      max_step_((control == StepControl::kDisplacement ? options.fast_step_fraction : options.max_step_fraction) *
                mesh_.spacing()),
      active_(&system),
      active_solver_(&solver),
      mu_(mu0) {
  if (system.num_dofs() != k.num_dofs() && (control != StepControl::kDisplacement || options.check_stability))
    throw std::logic_error("run_continuation: a subspace settle is the fast control without the stability check");
  model_.forces(state_, state_.x, f_);
  residual_ = system_.gather(f_);
  start_norm_ = system_.force_norm(residual_);
  halved_norm_ = start_norm_;
}

void Continuation::run(int max_iterations) {
  for (int it = 0; it < max_iterations; ++it, ++report_.iterations) {
    if (options_.interrupted && options_.interrupted()) throw SettleInterrupted();
    if (pushed_at_ >= 0 && it - pushed_at_ > options_.push_iterations) return settle_for_pushed_from();
    report_.residual_n = max_free_force(f_, fixed_);
    if (report_.residual_n < options_.force_tolerance_n) {
      if (at_equilibrium(it)) return;
      continue;
    }
    if (stalled(it)) break;
    if (take_step()) return;
  }
  if (pushed_at_ >= 0) return settle_for_pushed_from();
  report_.residual_n = max_free_force(f_, fixed_);
}

// Accepts a converged state, or pushes off the saddle it is on.
bool Continuation::at_equilibrium(int it) {
  pushed_at_ = -1;
  if (!options_.check_stability || report_.restarts >= options_.max_restarts) {
    report_.converged = true;
    return true;
  }
  k_.set_zero();
  model_.add_stiffness(state_, state_.x, k_);
  found_symmetry_.reset();
  DivergenceSearch search(k_.matrix());
  if (known_mode_remains(search)) {
    report_.converged = report_.marginal = true;
    return true;
  }
  const Eigen::VectorXd mode = search.mode();
  if (mode.size() == 0) {
    report_.converged = true;
    return true;
  }
  if (memory_.marginal_mode.size() == mode.size() && std::abs(memory_.marginal_mode.dot(mode)) > kSameMode) {
    report_.converged = report_.marginal = true;
    return true;
  }
  push_off(mode, it);
  return false;
}

// Whether the mode a push has already shown to lead nowhere is still there:
// asked first, since its direction barely turns from one action to the
// next on the same device, and a few solves from it beat the full search.
// At a mirror-symmetric state it is asked of the mode's symmetry class only.
bool Continuation::known_mode_remains(DivergenceSearch& search) {
  const std::optional<bool> known_in_class =
      memory_.marginal_mode.size() > 0
          ? still_has_in_mirror_class(mesh_, k_, symmetry(), memory_.marginal_mode, kSameMode)
          : std::nullopt;
  return known_in_class ? *known_in_class : search.still_has(memory_.marginal_mode, kSameMode);
}

// Pushes off the saddle along `mode` by a small fraction of h, to relax again.
void Continuation::push_off(const Eigen::VectorXd& mode, int it) {
  Eigen::Matrix3Xd push = k_.scatter(mode);
  active_ = &system_;
  active_solver_ = &solver_;
  if (control_ == StepControl::kDisplacement && !symmetry().trivial()) keep_push_in_mirror_class(push);
  Eigen::Index r = 0, c = 0;
  const double largest = push.cwiseAbs().maxCoeff(&r, &c);
  if (push(r, c) < 0) push = -push;  // a deterministic choice of side
  pushed_from_ = state_.x;
  pushed_mode_ = mode;
  pushed_at_ = it;
  push_refusals_ = 0;
  state_.x += (0.05 * mesh_.spacing() / largest) * push;
  unshifted_current_ = false;
  model_.forces(state_, state_.x, f_);
  residual_ = active_->gather(f_);
  mu_ = mu0_;
  ++report_.restarts;
  halved_norm_ = active_->force_norm(residual_);
  halved_at_ = it;
}

// The mode lies in one symmetry class (K keeps them apart): pushed along its
// part there, the surface keeps the mirrors that class keeps, and settles
// on their displacements.
void Continuation::keep_push_in_mirror_class(Eigen::Matrix3Xd& push) {
  const MirrorClass mode_class = strongest_mirror_class(mesh_, push, symmetry(), fixed_);
  if (!(mode_class.norm > 0.999 * push.norm())) return;
  push = mirror_projection(mesh_, push, symmetry(), mode_class.odd, fixed_);
  if (const MirrorGroup kept = mirror_kernel(symmetry(), mode_class.odd); !kept.trivial()) {
    push_subspace_ = std::make_unique<MirrorSubspace>(mesh_, k_, kept);
    push_system_ = std::make_unique<StepSystem>(k_, *push_subspace_);
    push_solver_ = std::make_unique<ShiftedSolver>();
    active_ = push_system_.get();
    active_solver_ = push_solver_.get();
  }
}

// Tracks when the residual last halved; true when a careful control has
// gone stall_iterations without (nothing to converge to), or the fast one
// kFastStallIterations (outside a push, whose steps climb out of a saddle).
bool Continuation::stalled(int it) {
  if (const double norm = active_->force_norm(residual_); norm < 0.5 * halved_norm_) {
    halved_norm_ = norm;
    halved_at_ = it;
    return false;
  }
  const int limit = control_ == StepControl::kDisplacement ? kFastStallIterations : options_.stall_iterations;
  return pushed_at_ < 0 && it - halved_at_ > limit;
}

// One step: a trial, judged by the control, taken or refused.
bool Continuation::take_step() {
  std::optional<Trial> trial = trial_step();
  if (!trial) {
    mu_ = std::max(4.0 * mu_, mu0_);
    return false;
  }
  const Verdict verdict =
      control_ == StepControl::kDisplacement ? judge_displacement(*trial) : judge_model_trust(*trial);
  if (verdict == Verdict::kAccept) accept(*trial);
  return verdict == Verdict::kStop;
}

// Solves the shifted system at state.x and tries its step, capped at
// max_step; nothing where the solve failed.
std::optional<Continuation::Trial> Continuation::trial_step() {
  if (!unshifted_current_) {
    active_->assemble(model_, state_, state_.x);
    unshifted_current_ = true;
  }
  active_->set_shift(mu_);
  Trial trial;
  const double largest = active_solver_->solve(active_->matrix(), mu_, residual_, trial.full_step)
                             ? active_->scatter(trial.full_step).colwise().norm().maxCoeff()
                             : NAN;
  if (!std::isfinite(largest)) return std::nullopt;
  const Eigen::Matrix3Xd move = active_->scatter(trial.full_step);
  trial.scale = std::min(1.0, max_step_ / move.colwise().norm().maxCoeff());
  trial.x = state_.x + trial.scale * move;
  model_.forces(state_, trial.x, f_trial_);
  trial.residual = active_->gather(f_trial_);
  trial.old_norm = active_->force_norm(residual_);
  trial.new_norm = active_->force_norm(trial.residual);
  return trial;
}

// The fast control: a step is refused when it raises the residual tenfold.
Continuation::Verdict Continuation::judge_displacement(const Trial& trial) {
  // Heading away (stiff jammed cells turned by straight strides): leave it
  // to the careful control rather than spend the budget.
  if (pushed_at_ < 0 && trial.new_norm > kAbandonGrowth * start_norm_) return Verdict::kStop;
  if (!(trial.new_norm < 10.0 * trial.old_norm)) {
    if (pushed_at_ >= 0 && ++push_refusals_ >= kPushRefusals) {
      settle_for_pushed_from();
      return Verdict::kStop;
    }
    mu_ = std::max(4.0 * mu_, mu0_);
    return Verdict::kRefuse;
  }
  mu_ = trial.scale < 1.0 ? std::max(mu_, 1e-6 * mu0_) * std::min(10.0, 1.0 / trial.scale) : 0.3 * mu_;
  return Verdict::kAccept;
}

// The careful control. rho: the error of the linear model's predicted
// residual, F - K s dx = (1 - s) F + s mu dx, measured in the
// compliance-weighted norm, i.e. after (K + mu I)^-1 (two more solves with
// the same LU). In the plain norm the stiff springs of jammed cells
// dominate it, and steps whose error those springs take back at once were
// refused.
Continuation::Verdict Continuation::judge_model_trust(const Trial& trial) {
  const double scale = trial.scale;
  Eigen::VectorXd correction, compliance_step;
  const bool solved = active_solver_->solve_again(active_->matrix(), mu_, trial.residual, correction) &&
                      active_solver_->solve_again(active_->matrix(), mu_, trial.full_step, compliance_step);
  const Eigen::VectorXd predicted = (1.0 - scale) * trial.full_step + (scale * mu_) * compliance_step;
  const double rho = solved ? (correction - predicted).norm() / std::max((trial.full_step - predicted).norm(), 1e-300)
                            : INFINITY;
  if (!(rho <= 1.0)) {
    refused_mu_ = std::max(refused_mu_, mu_);
    ++refusals_;
    mu_ = std::max(4.0 * mu_, mu0_);
    return Verdict::kRefuse;
  }
  mu_ *= rho < 0.1 ? 0.1 : rho < 0.3 ? 0.3 : 0.7;
  // Once refusals pile up, not back below twice the shift last refused (a
  // bound that halves with each accepted step): the shift otherwise can
  // cycle between an accepted mu0 and a refused mu0 / 10 for good (6 x 8
  // volcano plan, 35 cells jammed, 300 -> 350 Pa). Only then: in settles
  // that converge without it, it changes which of two nearby equilibria
  // some reach.
  if (refusals_ > kRefusalsBeforeMemory) {
    mu_ = std::max(mu_, 2.0 * refused_mu_);
    refused_mu_ *= 0.5;
  }
  return Verdict::kAccept;
}

void Continuation::accept(Trial& trial) {
  state_.x = trial.x;
  unshifted_current_ = false;
  f_.swap(f_trial_);
  residual_ = std::move(trial.residual);
  if (mu_ < 1e-10 * mu0_) mu_ = 0.0;
}

// A push that has not led to another equilibrium within its budget was
// along a mode too weak to matter: settle for the equilibrium it left.
void Continuation::settle_for_pushed_from() {
  state_.x = pushed_from_;
  memory_.marginal_mode = pushed_mode_;
  model_.forces(state_, state_.x, f_);
  report_.residual_n = max_free_force(f_, fixed_);
  report_.converged = report_.marginal = true;
}

MirrorGroup Continuation::symmetry() {
  if (!found_symmetry_)
    found_symmetry_ = options_.mirror_symmetry ? mirror_symmetry_of(model_, state_) : MirrorGroup{};
  return *found_symmetry_;
}

}  // namespace

void run_continuation(const ForceModel& model, DeviceState& state, StiffnessMatrix& k, StepSystem& system,
                      ShiftedSolver& solver, const std::vector<char>& fixed, const StaticSolverOptions& options,
                      StepControl control, int max_iterations, double mu0, SettleMemory& memory,
                      SettleReport& report) {
  Continuation(model, state, k, system, solver, fixed, options, control, mu0, memory, report).run(max_iterations);
}

}  // namespace hj
