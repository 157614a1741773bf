#include "sim/simulator.h"

#include <algorithm>
#include <optional>
#include <stdexcept>
#include <utility>

#include "sim/coarse_start.h"
#include "sim/dead_end_watch.h"
#include "sim/effect_registry.h"
#include "sim/jamming_springs.h"
#include "sim/levelling_crossing.h"
#include "sim/mesh_folds.h"

namespace hj {

namespace {

// The static solver's first shift (x spring_k) from a start within a few
// Newton steps of the equilibrium (the coarse mesh's dome): not the heavily
// damped relaxation of a start from afar (9 x 12, rest to 2 kPa: 9 fine
// steps at the default 0.1, 7 at 1e-3 or 1e-4).
constexpr double kCloseStartShift = 1e-3;

}  // namespace

SolverKind parse_solver_kind(const std::string& name) {
  if (name == "static") return SolverKind::kStatic;
  if (name == "explicit") return SolverKind::kExplicit;
  throw std::invalid_argument("unknown solver \"" + name + "\": use static or explicit");
}

Simulator::Simulator(const ArrayGeometry& geometry, const SurfaceParameters& params, SimulatorOptions options)
    : options_(std::move(options)), model_(Mesh(geometry), params, make_effects(options_.extra_effects, options_.effect_parameters)) {
  options_.static_options.validate();
  options_.explicit_options.validate();
  options_.flow_options.validate();
  if (!(options_.refuse_fold_deg >= 90.0 && options_.refuse_fold_deg <= 180.0))
    throw std::invalid_argument("simulator option refuse_fold_deg (degrees) must lie in [90, 180]");
  if (!(options_.stall_fold_deg >= 90.0 && options_.stall_fold_deg <= options_.refuse_fold_deg))
    throw std::invalid_argument("simulator option stall_fold_deg (degrees) must lie in [90, refuse_fold_deg]");
  if (options_.refuse_stall_steps < 0)
    throw std::invalid_argument("simulator option refuse_stall_steps must be >= 0 (0: no limit)");
  if (options_.fallback_max_steps < 0)
    throw std::invalid_argument("simulator option fallback_max_steps must be >= 0 (0: no explicit fallback)");
  if (options_.max_settle_steps < 0)
    throw std::invalid_argument("simulator option max_settle_steps must be >= 0 (0: no limit)");
  install_poll();
  // Below this many free DOFs a settle step costs well under a millisecond
  // and the mirrored start's few steps are not worth a second mesh.
  constexpr int kCoarseStartMinDofs = 1500;
  const Mesh& mesh = model_.mesh();
  const int free_dofs = 3 * (mesh.point_rows() - 2) * (mesh.point_cols() - 2);
  if (const int coarse = coarse_segments(mesh.segments());
      options_.coarse_start && options_.solver == SolverKind::kStatic && coarse > 0 && free_dofs >= kCoarseStartMinDofs) {
    ArrayGeometry g = mesh.geometry();
    g.segments = coarse;
    coarse_model_ = std::make_unique<ForceModel>(Mesh(g), params,
                                                 make_effects(options_.extra_effects, options_.effect_parameters));
  }
  state_ = DeviceState::flat(model_.mesh());
  settle();
}

void Simulator::settle(bool fallbacks) {
  settle_once(fallbacks);
  // Effects that change the state at equilibrium (jam creep) do so once per
  // settle; the surface then settles to the changed state.
  if (last_.converged && model_.after_settle(state_)) {
    const SettleReport first = last_;
    settle_once(fallbacks);
    last_.iterations += first.iterations;
    last_.seconds += first.seconds;
    last_.restarts += first.restarts;
  }
}

void Simulator::settle_once(bool fallbacks) {
  if (options_.solver == SolverKind::kExplicit) {
    last_ = settle_explicit(model_, state_, options_.explicit_options);
    return;
  }
  if (keeps_equilibrium_) {
    // A jam or pin at a stable equilibrium: still one, if the residual says so.
    Eigen::Matrix3Xd f;
    model_.forces(state_, state_.x, f);
    const double residual = max_free_force(f, model_.fixed_points(state_));
    if (residual < options_.static_options.force_tolerance_n) {
      last_ = SettleReport{true};
      last_.residual_n = residual;
      return;
    }
  }
  const Eigen::Matrix3Xd before = state_.x;
  SettleReport tried;  // what the fast control and the flow spent first
  if (fallbacks && options_.flow_fallback && options_.flow_first && options_.static_options.fast_iterations > 0) {
    if (settle_fast_then_flow(before)) return;
    if (dead_end_) return;
    tried = last_;
  }
  StaticSolverOptions static_options = options_.static_options;
  if (close_start_) static_options.initial_shift = std::min(static_options.initial_shift, kCloseStartShift);
  if (controls_ == Controls::kFastOnly) static_options.careful = false;
  if (controls_ == Controls::kCarefulOnly) static_options.fast_iterations = 0;
  last_ = settle_static(model_, state_, static_options, &settle_memory_);
  if (!last_.converged && fallbacks) settle_fallbacks(before);
  last_.iterations += tried.iterations;
  last_.seconds += tried.seconds;
}

bool Simulator::settle_fast_then_flow(const Eigen::Matrix3Xd& before) {
  StaticSolverOptions fast_only = options_.static_options;
  fast_only.careful = false;
  last_ = settle_static(model_, state_, fast_only, &settle_memory_);
  if (last_.converged) return true;
  SettleReport spent = last_;
  state_.x = before;
  if (flow_then_polish(1, spent)) return true;
  if (*flow_dead_end_) {
    // The model's own dynamics lead into a fold: a dead end for a planner.
    dead_end_ = true;
    last_ = spent;
    last_.converged = false;
    return false;
  }
  // Neither: the careful controls from the start, as without this.
  state_.x = before;
  last_ = SettleReport{};
  last_.iterations = spent.iterations;
  last_.seconds = spent.seconds;
  return false;
}

bool Simulator::polish(const SettleReport& fallback, SettleReport& spent) {
  spent.iterations += fallback.iterations;
  spent.seconds += fallback.seconds;
  last_ = settle_static(model_, state_, options_.static_options, &settle_memory_);
  last_.iterations += spent.iterations;
  last_.seconds += spent.seconds;
  last_.restarts += spent.restarts;
  spent = last_;
  return last_.converged;
}

ImplicitFlowOptions Simulator::flow_options() {
  ImplicitFlowOptions options = options_.flow_options;
  flow_dead_end_ = "";
  if (options_.refuse_folded) {
    DeadEndWatchOptions watch_options;
    watch_options.refuse_fold_deg = options_.refuse_fold_deg;
    watch_options.stall_fold_deg = options_.stall_fold_deg;
    watch_options.stall_steps = options_.refuse_stall_steps;
    options.abandon = [this, watch = std::make_shared<DeadEndWatch>(mesh(), watch_options)](
                          const Eigen::Matrix3Xd& x, double residual_n) {
      if (!watch->dead_end(x, residual_n)) return false;
      flow_dead_end_ = watch->reason();
      return true;
    };
  }
  return options;
}

bool Simulator::flow_then_polish(int rounds, SettleReport& spent) {
  for (int round = 0; round < rounds; ++round) {
    const SettleReport flow = settle_implicit_flow(model_, state_, flow_options());
    if (!flow.converged) {
      spent.iterations += flow.iterations;
      spent.seconds += flow.seconds;
      return false;
    }
    if (polish(flow, spent)) return true;
  }
  return false;
}

void Simulator::settle_fallbacks(const Eigen::Matrix3Xd& before) {
  SettleReport spent = last_;
  if (options_.flow_fallback) {
    state_.x = before;
    if (flow_then_polish(3, spent)) return;
  }
  if (options_.fallback_max_steps == 0) {
    last_ = spent;
    last_.converged = false;
    return;
  }
  // The paper's dynamics from the previous state, then polished.
  state_.x = before;
  ExplicitEulerOptions fallback = options_.explicit_options;
  fallback.max_steps = std::min(fallback.max_steps, options_.fallback_max_steps);
  polish(settle_explicit(model_, state_, fallback), spent);
}

void Simulator::install_poll() {
  budget_->limit = options_.max_settle_steps;
  if (!options_.interrupted && budget_->limit == 0) return;
  options_.static_options.interrupted = options_.explicit_options.interrupted = options_.flow_options.interrupted =
      [interrupted = options_.interrupted, budget = budget_] {
        if (interrupted && interrupted()) return true;
        if (!budget->counting || budget->limit == 0 || ++budget->used <= budget->limit) return false;
        budget->exceeded = true;
        return true;
      };
}

const SettleReport& Simulator::apply(const Action& action) { return apply_from(action, nullptr); }

void Simulator::rewind(const Checkpoint& checkpoint) {
  if (checkpoint.state.x.cols() != state_.x.cols() || checkpoint.state.cell_jammed.size() != state_.cell_jammed.size() ||
      checkpoint.state.node_pinned.size() != state_.node_pinned.size())
    throw std::invalid_argument("Simulator::rewind: the checkpoint is of another mesh");
  state_ = checkpoint.state;
  settle_memory_ = checkpoint.memory;
  last_ = checkpoint.last;
}

const SettleReport& Simulator::apply(const Action& action, const Eigen::Matrix3Xd& start) {
  if (start.cols() != state_.x.cols())
    throw std::invalid_argument("Simulator::apply: start has " + std::to_string(start.cols()) + " points, the mesh " +
                                std::to_string(state_.x.cols()));
  return apply_from(action, &start);
}

const SettleReport& Simulator::apply_from(const Action& action, const Eigen::Matrix3Xd* start) {
  action.validate(mesh(), params());
  dead_end_ = false;
  flow_dead_end_ = "";
  const DeviceState before = state_;
  const Mesh& m = mesh();
  std::optional<Eigen::Matrix3Xd> predicted;
  bool predicted_from_coarse = false;
  switch (action.op) {
    case Action::Op::kSetPressure:
      if (!start && options_.solver == SolverKind::kStatic) {
        if (coarse_model_) {
          if (auto coarse = coarse_mesh_start(model_, *coarse_model_, state_, action.pressure_pa,
                                              options_.static_options)) {
            predicted = std::move(coarse->x);
            predicted_from_coarse = true;
            if (coarse->marginal_mode.size() > 0) settle_memory_.marginal_mode = std::move(coarse->marginal_mode);
          }
        }
        if (!predicted) predicted = levelling_crossing_start(model_, state_, action.pressure_pa);
        if (predicted) start = &*predicted;
      }
      state_.pressure_pa = action.pressure_pa;
      break;
    case Action::Op::kJam:
      if (state_.jammed(m, action.a, action.b)) {  // already jammed: nothing changes
        last_ = SettleReport{true};
        return last_;
      }
      state_.cell_jammed[m.cell_index(action.a, action.b)] = 1;
      // The cell keeps the bend it has now: phi_eq = phi.
      for (int p : m.cell_interior(action.a, action.b))
        for (const BendSpring& s : bend_springs_at(m, p)) state_.phi_eq(s.axis, p) = bend_angle_of(state_.x, s);
      break;
    case Action::Op::kUnjam:
      state_.cell_jammed[m.cell_index(action.a, action.b)] = 0;
      break;
    case Action::Op::kPin:
      state_.node_pinned[m.node_index(action.a, action.b)] = 1;
      break;
    case Action::Op::kUnpin:
      state_.node_pinned[m.node_index(action.a, action.b)] = 0;
      break;
  }
  keeps_equilibrium_ = options_.skip_settle_after_jam_or_pin &&
                       (action.op == Action::Op::kJam || action.op == Action::Op::kPin);
  // Such an action settles from the state as it is, not from a warm start:
  // that is an equilibrium already, while the start was settled under other
  // parameters and takes a full settle (jammed-sweep of demo-bending under a
  // mass 0.01 % off: 7-8 Newton steps at each of its 12 jams).
  if (keeps_equilibrium_) start = nullptr;
  *budget_ = StepBudget{budget_->limit, 0, true, false};
  try {
    const Eigen::Matrix3Xd cold = state_.x;
    SettleReport tried;  // what the starts spent, where they failed
    if (start) {
      const bool settled = predicted ? settle_from_prediction(cold, *start, predicted_from_coarse)
                                     : settle_trial_from(*start, Controls::kBoth, false);
      if (!settled) {
        tried = last_;
        state_.x = cold;
      }
    }
    if (!start || !last_.converged) {
      settle();
      last_.iterations += tried.iterations;
      last_.seconds += tried.seconds;
    }
  } catch (const SettleInterrupted&) {
    keeps_equilibrium_ = close_start_ = budget_->counting = false;
    controls_ = Controls::kBoth;
    state_ = before;
    if (budget_->exceeded)
      throw NoEquilibrium("no static equilibrium found within " + std::to_string(budget_->limit) +
                          " solver steps after " + action.describe());
    throw;
  } catch (...) {
    keeps_equilibrium_ = close_start_ = budget_->counting = false;
    controls_ = Controls::kBoth;
    state_ = before;
    throw;
  }
  keeps_equilibrium_ = budget_->counting = false;
  if (!last_.converged) {
    // Where the settle stopped: a folded mesh is the usual reason (mesh_folds.h).
    const std::string folds = find_mesh_folds(m, state_.x).describe();
    const std::string why = *flow_dead_end_ ? std::string("; the flow ") + flow_dead_end_ : "";
    state_ = before;
    throw NoEquilibrium("no static equilibrium found after " + action.describe() + " (residual " +
                        std::to_string(last_.residual_n) + " N" + (folds.empty() ? "" : "; " + folds) + why + ")");
  }
  if (options_.refuse_folded) {
    if (const MeshFolds folds = find_mesh_folds(m, state_.x); folds.sharpest_deg > options_.refuse_fold_deg) {
      state_ = before;
      throw NoEquilibrium("the equilibrium after " + action.describe() + " is folded: " + folds.describe());
    }
  }
  return last_;
}

bool Simulator::settle_trial_from(const Eigen::Matrix3Xd& from, Controls controls, bool close) {
  const std::vector<char> fixed = model_.fixed_points(state_);
  for (int p = 0; p < mesh().num_points(); ++p)
    if (!fixed[p]) state_.x.col(p) = from.col(p);
  close_start_ = close;
  controls_ = controls;
  settle(/*fallbacks=*/false);
  close_start_ = false;
  controls_ = Controls::kBoth;
  return last_.converged;
}

// The careful control from a prediction near levelling, where the slack
// net's landscape is flat, can creep for its whole budget (6 x 8 at p = 8,
// a 300 Pa sag to 350 Pa from the coarse dome: 1000 steps, unconverged)
// where the fast control from the sag settles in 13; elsewhere it is the
// only way (6 x 8 at p = 8 with stiffening, rest to 375 Pa: 471 careful
// steps from the coarse dome, while the flow from rest does not settle in
// 400). So the cheap tries come first.
bool Simulator::settle_from_prediction(const Eigen::Matrix3Xd& cold, const Eigen::Matrix3Xd& prediction,
                                       bool from_coarse) {
  SettleReport spent;
  for (const auto& [from, controls] : {std::pair{&prediction, Controls::kFastOnly}, std::pair{&cold, Controls::kFastOnly},
                                       std::pair{&prediction, Controls::kCarefulOnly}}) {
    const bool settled = settle_trial_from(*from, controls, from_coarse && from == &prediction);
    spent.iterations += last_.iterations;
    spent.seconds += last_.seconds;
    if (settled) break;
  }
  last_.iterations = spent.iterations;
  last_.seconds = spent.seconds;
  return last_.converged;
}

}  // namespace hj
