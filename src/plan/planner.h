// The planner interface: a goal surface in, an action sequence and the
// surface it makes out (paper section 5). Planners register by name, so a
// new one is one new file in src/plan/.
#pragma once

#include <Eigen/Core>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "model/action.h"
#include "model/device_state.h"
#include "model/parameters.h"
#include "sim/simulator.h"

namespace hj {

// How a planner judges a surface against the goal, where it chooses among
// candidates: the paper's correlation (Eq. 12), blind to scale, or, for a
// goal whose millimetres are meant (absolute heights, the render loop's
// targets), the closeness of the heights at the mesh points.
enum class PlanScoring { kCorrelation, kHeightError };

struct PlanRequest {
  ArrayGeometry geometry;
  SurfaceParameters params;
  // ((R p + 1) x (C p + 1)) goal height of each mesh point (i, j), mm.
  Eigen::MatrixXd goal_mm;
  SimulatorOptions simulator;
  // The goal image the plan is scored against (Eq. 12; row 0 at the top),
  // if the caller has it; empty: plans are compared at the mesh points.
  Eigen::MatrixXd goal_image;
  PlanScoring scoring = PlanScoring::kCorrelation;
  // Up to this multiple of the levelling pressure a device departs most from
  // the model: where its sag turns into a dome hangs on its mass, its
  // stiffening and the mesh (a free 6 x 8 net at 1.12 x levelling domes at
  // p = 4 and, stiffening, still sags at p = 8). The variants that jam only above levelling
  // (algorithm2-levelled) take no action below it and carry the free net
  // there in one step. 1: at the levelling pressure, for plans judged in the
  // model; a render on a device sets more (server/render_loop.cc).
  double levelling_margin = 1.0;
};

struct PlanCallbacks {
  // Fraction done in [0, 1] and what is happening.
  std::function<void(double fraction, const std::string& what)> progress;
  // The settled state after an action, for streaming snapshots.
  std::function<void(const DeviceState& state)> snapshot;
  // Polled between actions; true stops the plan with PlanCancelled.
  std::function<bool()> cancelled;
};

// An action a planner tried and did not take: its settle found no static
// equilibrium, or one with the mesh folded (mesh_folds.h), a dead end the
// model cannot follow reliably.
struct RefusedAction {
  Action action;
  std::string reason;
  int after_step = 0;  // how many of the plan's steps came before it
};

struct PlanResult {
  std::vector<Action> steps;  // in the order to apply them, from rest
  DeviceState final_state;    // the predicted surface
  std::vector<RefusedAction> refused;
  // Wall time of the settles the plan kept and of those it refused, s:
  // where the planner's time went.
  double settle_seconds = 0.0;
  double refused_seconds = 0.0;
  // How the planner came to it, for people (e.g. the strategy a portfolio
  // chose and the scores of the others); may be empty.
  std::string note;
};

class PlanCancelled : public std::runtime_error {
 public:
  PlanCancelled() : std::runtime_error("planning was cancelled") {}
  // The plan so far when the planner was stopped between or inside its
  // actions: its steps replay from rest to its final_state, a settled
  // equilibrium. A caller that stopped a planner at a time budget may keep it.
  explicit PlanCancelled(PlanResult so_far)
      : std::runtime_error("planning was cancelled"), partial_(std::make_shared<PlanResult>(std::move(so_far))) {}
  const PlanResult* partial() const { return partial_.get(); }

 private:
  std::shared_ptr<const PlanResult> partial_;  // shared: exceptions are copied
};

class Planner {
 public:
  virtual ~Planner() = default;
  virtual std::string name() const = 0;
  // Throws std::invalid_argument on a goal whose shape does not match the
  // mesh or holds non-finite heights; PlanCancelled when cancelled.
  virtual PlanResult plan(const PlanRequest& request, const PlanCallbacks& callbacks = {}) const = 0;
};

// Planners by name; each planner file registers itself.
std::unique_ptr<Planner> make_planner(const std::string& name);
std::vector<std::string> planner_names();
void register_planner(const std::string& name, std::function<std::unique_ptr<Planner>()> make);

// The request's simulator options with callbacks.cancelled polled inside
// every settle too, so a cancel stops a long settle, not only the plan
// between actions (catch SettleInterrupted, throw PlanCancelled); folded
// equilibria refused (SimulatorOptions::refuse_folded); no explicit fallback.
SimulatorOptions simulator_options(const PlanRequest& request, const PlanCallbacks& callbacks);
// Solver steps a planner's settle may take before the action is refused as a
// dead end (SimulatorOptions::max_settle_steps).
constexpr int kPlannerSettleSteps = 150;

// The request's simulator settled at rest, its settles cancellable
// (SettleInterrupted becomes PlanCancelled).
Simulator start_simulator(const PlanRequest& request, const PlanCallbacks& callbacks);

// Applies one planned action: cancellation checked first, a cancelled
// settle thrown as PlanCancelled carrying the plan so far (result with the
// simulator's state, which a cancelled settle leaves as it was), the action
// recorded in result.steps and the state sent to callbacks.snapshot.
void apply_planned(Simulator& sim, const Action& action, PlanResult& result, const PlanCallbacks& callbacks);

// As apply_planned, but a settle with no (unfolded) equilibrium is a dead
// end, not the end of the plan: the simulator keeps the state it had, the
// action goes to result.refused with the reason, and false is returned.
bool try_planned(Simulator& sim, const Action& action, PlanResult& result, const PlanCallbacks& callbacks);

// A point of a plan to come back to: the simulator's checkpoint and how many
// steps the plan had. A planner that tries an action it may not keep (a
// pressure step too far, an end pressure that scores worse) rewinds to it
// rather than acting its way back, so the plan, and the device, never make
// the action, and the state it ends in is the one it scored.
struct PlanCheckpoint {
  Simulator::Checkpoint simulator;
  std::size_t steps = 0;
};
PlanCheckpoint plan_checkpoint(const Simulator& sim, const PlanResult& result);
void rewind_plan(Simulator& sim, PlanResult& result, const PlanCheckpoint& checkpoint);

// The side from which a rising (Algorithm 2) or falling (from-above)
// surface reaches its goal: a node's height or a cell's curvature at or
// above the goal's, or at or below it.
enum class Reach { kFromBelow, kFromAbove };

// Pins, in row-major order, every free node that has reached its goal
// height (goal_x: 3 x N, m); true if every node is then pinned.
bool pin_reached_nodes(Simulator& sim, const Eigen::Matrix3Xd& goal_x, Reach reach, PlanResult& result,
                       const PlanCallbacks& callbacks);
// Jams, in row-major order, every free cell whose curvature (Eq. 11) has
// reached its goal cell's ((R x C)); true if every cell is then jammed.
bool jam_reached_cells(Simulator& sim, const Eigen::MatrixXd& goal_curvature, Reach reach, PlanResult& result,
                       const PlanCallbacks& callbacks);
// True if every cell of the state is jammed.
bool every_cell_jammed(const Mesh& mesh, const DeviceState& state);
// Nothing jammed and nothing pinned.
bool is_free_net(const Mesh& mesh, const DeviceState& state);

// The goal as a surface on the mesh: rest positions with z = scale * goal_mm / 1000 (3 x N, m).
Eigen::Matrix3Xd goal_positions(const Mesh& mesh, const Eigen::MatrixXd& goal_mm, double scale = 1.0);

// How well a state matches the request's goal, higher is better: with
// kCorrelation, Eq. 12 against goal_image when given, else the correlation
// with goal_mm at the mesh points; with kHeightError, minus the RMSE (mm)
// against goal_mm at the mesh points. -inf where undefined. The portfolio
// chooses its strategy by it.
double plan_score(const PlanRequest& request, const Mesh& mesh, const DeviceState& state);
// The same at the mesh points only (heights_mm as point_heights, in mm):
// what a planner's own choices (an end pressure, a variant) maximise.
double mesh_point_score(const PlanRequest& request, const Eigen::MatrixXd& heights_mm);
// The same of a state's heights.
double mesh_point_score(const PlanRequest& request, const Mesh& mesh, const DeviceState& state);

// A planner's pressure ceiling: its option (0: none) capped by the device's.
double plan_max_pressure(double option_pa, const SurfaceParameters& params);

// Checks a request's goal against its mesh (shape, finite values) and its
// levelling margin (1 to kMaxLevellingMargin).
constexpr double kMaxLevellingMargin = 4.0;
void validate_plan_request(const PlanRequest& request, const Mesh& mesh);

}  // namespace hj
