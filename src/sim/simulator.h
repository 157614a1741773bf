// The simulated device: a force model, a state, and the five actions, each
// followed by a settle to static equilibrium from the state before it
// (docs/model.md, "States and actions").
#pragma once

#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "model/action.h"
#include "sim/effect_registry.h"
#include "sim/explicit_euler.h"
#include "sim/force_model.h"
#include "sim/implicit_flow.h"
#include "sim/static_solver.h"

namespace hj {

enum class SolverKind { kStatic, kExplicit };

struct SimulatorOptions {
  SolverKind solver = SolverKind::kStatic;
  StaticSolverOptions static_options;
  ExplicitEulerOptions explicit_options;
  // Where the static solver does not settle (a snap-through: the jammed
  // sag's equilibrium vanishes as the pressure rises), the implicit flow
  // follows the surface to the next equilibrium, which the static solver
  // then polishes and checks for stability (sim/implicit_flow.h).
  bool flow_fallback = true;
  ImplicitFlowOptions flow_options;
  // Where the static solver's fast control does not settle, the implicit
  // flow (then polished by the static solver) before its careful controls:
  // on large moves of jammed plates it takes far fewer steps and reaches
  // the same equilibria (tests/flow_first_test.cc). Settles that must not
  // use the fallbacks (Simulator::settle with fallbacks off) keep the
  // careful controls.
  bool flow_first = true;
  // Steps the explicit fallback, the last resort after the flow, may take
  // before the settle is reported as failed (bounds the time of a hard
  // case); 0: no explicit fallback.
  long fallback_max_steps = 2'000'000;
  // A jam at equilibrium only adds positive semi-definite stiffness
  // (phi_eq = phi) and a pin only removes DOFs: the state stays a stable
  // equilibrium, so their settle ends at once, without building K or
  // checking stability, when the residual is already below tolerance (a
  // planner jams and pins many times). Unjam and unpin
  // can destabilise and always settle in full.
  bool skip_settle_after_jam_or_pin = true;
  // A free net carried across levelling on a large mesh (at least 1,500
  // free DOFs, p >= 4) starts from the same settle on a mesh of half the
  // segments (coarse_start.h) rather than from the mirrored sag alone.
  bool coarse_start = true;
  // With refuse_folded, a state whose sharpest fold (mesh_folds.h) turns
  // back by more than refuse_fold_deg, where the Eq. 3 normals are nearly
  // ill-defined, counts as no equilibrium (apply throws NoEquilibrium and
  // leaves the state as it was), and a flow that reaches one stops there.
  // Planners set it: such a settle is a dead end.
  bool refuse_folded = false;
  double refuse_fold_deg = 150.0;
  // With refuse_folded, a flow folded past stall_fold_deg that comes back
  // within a quarter of the mesh spacing of a state it passed at least
  // refuse_stall_steps accepted steps before, its residual not halved since,
  // is a dead end too (sim/dead_end_watch.h); 0 steps: no such limit.
  double stall_fold_deg = 120.0;
  int refuse_stall_steps = 20;
  // Effects beyond the baseline, by registry name, and their parameter
  // values (effect name -> parameter name -> value; missing = default).
  std::vector<std::string> extra_effects;
  std::map<std::string, EffectParameterValues> effect_parameters;
  // Polled while settling; true makes apply() throw SettleInterrupted with
  // the state as it was before the action. Overrides the solvers' own.
  std::function<bool()> interrupted;
  // Solver steps (static and flow steps, explicit polls) one action's settle
  // may take, all stages together; past them apply() throws NoEquilibrium.
  // 0: no limit. Planners set it: a dead end must cost little.
  int max_settle_steps = 0;
};

class Simulator {
 public:
  // Builds the mesh and settles the rest state (P = 0, a sag). Throws
  // std::invalid_argument on a bad geometry, parameter or option.
  Simulator(const ArrayGeometry& geometry, const SurfaceParameters& params, SimulatorOptions options = {});

  const Mesh& mesh() const { return model_.mesh(); }
  const SurfaceParameters& params() const { return model_.params(); }
  const ForceModel& model() const { return model_; }
  const DeviceState& state() const { return state_; }
  const SettleReport& last_settle() const { return last_; }

  // The state as it is, with what its settles carry to the next one: a
  // planner's trial action it may not keep goes back here (rewind), so the
  // actions it keeps replay from rest to the same states.
  struct Checkpoint {
    DeviceState state;
    SettleMemory memory;
    SettleReport last;
  };
  Checkpoint checkpoint() const { return {state_, settle_memory_, last_}; }
  // Back to a checkpoint of this simulator. Throws std::invalid_argument if
  // it is of another mesh.
  void rewind(const Checkpoint& checkpoint);

  // Validates (std::invalid_argument naming what is wrong), applies and
  // settles. Repeating an action changes nothing. Throws NoEquilibrium if no
  // equilibrium is found, SettleInterrupted if interrupted (the state is left
  // as it was in both cases).
  const SettleReport& apply(const Action& action);
  // As apply(action), but the settle starts with the free points at `start`
  // (3 x N), e.g. the settled state of the same step under nearby
  // parameters, which a fit's Jacobian replays many times; fixed and pinned
  // points stay. If the static solver does not settle from there, settles
  // from the usual start (fallbacks included), so a start that fails costs
  // one static settle, not the whole fallback chain twice.
  const SettleReport& apply(const Action& action, const Eigen::Matrix3Xd& start);

 private:
  // Settles, then runs the effects' after_settle hooks (ForceModel) and,
  // if they changed the state, settles once more. Without fallbacks: the
  // static solver only (a trial from a start state).
  void settle(bool fallbacks = true);
  void settle_once(bool fallbacks);
  // The static solver failed from `before`: the implicit flow, then the
  // explicit fallback, each polished by the static solver.
  void settle_fallbacks(const Eigen::Matrix3Xd& before);
  // SimulatorOptions::flow_first: true if settled; else state_.x is `before`
  // again and last_ holds only what was spent.
  bool settle_fast_then_flow(const Eigen::Matrix3Xd& before);
  // The static solver's polish of a fallback's end state: last_ is its
  // report with everything spent so far added (spent becomes it); true if
  // it settled.
  bool polish(const SettleReport& fallback, SettleReport& spent);
  // The implicit flow from the current state, then the polish, for up to
  // `rounds` rounds: a polish that pushes off a saddle and does not settle
  // again leaves the state beside it, and the flow goes on from there.
  bool flow_then_polish(int rounds, SettleReport& spent);
  // options_.flow_options, with SimulatorOptions::refuse_folded: stopping
  // at a dead end (sim/dead_end_watch.h), which sets flow_dead_end_.
  ImplicitFlowOptions flow_options();
  const SettleReport& apply_from(const Action& action, const Eigen::Matrix3Xd* start);
  // A pressure change's settle from the simulator's own prediction (the
  // coarse mesh's dome, or the mirrored sag), without fallbacks: the fast
  // control from the prediction, then from the state as it is (`cold`),
  // then the careful control from the prediction. True if one settled;
  // last_ counts the steps of all it tried.
  bool settle_from_prediction(const Eigen::Matrix3Xd& cold, const Eigen::Matrix3Xd& prediction, bool from_coarse);
  // One settle without fallbacks from `from` (its free points), with the
  // static solver's controls limited as `controls` says.
  enum class Controls { kBoth, kFastOnly, kCarefulOnly };
  bool settle_trial_from(const Eigen::Matrix3Xd& from, Controls controls, bool close);

  // The steps the current action's settle has polled (max_settle_steps);
  // shared with the solvers' interrupted callbacks, so a moved simulator keeps it.
  struct StepBudget {
    int limit = 0;
    int used = 0;
    bool counting = false;
    bool exceeded = false;
  };
  // Installs the callback the solvers poll every step: the caller's
  // interrupted, then the step budget.
  void install_poll();

  SimulatorOptions options_;
  std::shared_ptr<StepBudget> budget_ = std::make_shared<StepBudget>();
  ForceModel model_;
  // The same effects on the coarser mesh (SimulatorOptions::coarse_start),
  // or null where the mesh is too small for it to pay.
  std::unique_ptr<ForceModel> coarse_model_;
  DeviceState state_;
  SettleReport last_;
  SettleMemory settle_memory_;
  // Set by apply_from while a jam or pin settles (skip_settle_after_jam_or_pin).
  bool keeps_equilibrium_ = false;
  // Set by apply_from while a settle starts from the coarse mesh's dome.
  bool close_start_ = false;
  // The static solver's controls in the settle under way (settle_trial_from).
  Controls controls_ = Controls::kBoth;
  // With refuse_folded: the flow from the state before the action reached a
  // dead end, so the settle ends there without the slower controls;
  // flow_dead_end_ says why ("" while the last flow was not abandoned).
  bool dead_end_ = false;
  const char* flow_dead_end_ = "";
};

// Parses "static" / "explicit"; std::invalid_argument otherwise.
SolverKind parse_solver_kind(const std::string& name);

}  // namespace hj
