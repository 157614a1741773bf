#include "plan/planner.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <sstream>

#include "metrics/correlation.h"
#include "sim/surface_measures.h"

namespace hj {

namespace {

std::map<std::string, std::function<std::unique_ptr<Planner>()>>& registry() {
  static std::map<std::string, std::function<std::unique_ptr<Planner>()>> planners;
  return planners;
}

}  // namespace

void register_planner(const std::string& name, std::function<std::unique_ptr<Planner>()> make) {
  if (!registry().emplace(name, std::move(make)).second)
    throw std::invalid_argument("planner \"" + name + "\" is registered twice");
}

std::vector<std::string> planner_names() {
  std::vector<std::string> names;
  for (const auto& [name, make] : registry()) names.push_back(name);
  return names;
}

std::unique_ptr<Planner> make_planner(const std::string& name) {
  const auto it = registry().find(name);
  if (it == registry().end()) {
    std::string known;
    for (const auto& n : planner_names()) known += (known.empty() ? "" : ", ") + n;
    throw std::invalid_argument("unknown planner \"" + name + "\"; known planners: " + known);
  }
  return it->second();
}

void validate_plan_request(const PlanRequest& request, const Mesh& mesh) {
  const auto& g = request.goal_mm;
  if (g.rows() != mesh.point_rows() || g.cols() != mesh.point_cols()) {
    std::ostringstream err;
    err << "goal has " << g.rows() << " x " << g.cols() << " heights; the mesh of a " << mesh.rows() << " x "
        << mesh.cols() << " array at p = " << mesh.segments() << " has " << mesh.point_rows() << " x "
        << mesh.point_cols() << " points";
    throw std::invalid_argument(err.str());
  }
  if (!g.allFinite()) throw std::invalid_argument("goal heights must all be finite numbers (mm)");
  if (!(request.levelling_margin >= 1.0 && request.levelling_margin <= kMaxLevellingMargin)) {
    std::ostringstream err;
    err << "levelling margin " << request.levelling_margin << " is outside [1, " << kMaxLevellingMargin
        << "] (a multiple of the levelling pressure)";
    throw std::invalid_argument(err.str());
  }
}

SimulatorOptions simulator_options(const PlanRequest& request, const PlanCallbacks& callbacks) {
  SimulatorOptions options = request.simulator;
  if (callbacks.cancelled) options.interrupted = callbacks.cancelled;
  options.refuse_folded = true;
  // No explicit Euler fallback: a settle that the static solver and the
  // implicit flow cannot finish is a dead end (refused), found in seconds.
  options.fallback_max_steps = 0;
  // The longest settles a plan keeps take about a hundred solver steps (the
  // first jammed steps past levelling on 7 x 10); a dead end is cut off soon after.
  options.max_settle_steps = kPlannerSettleSteps;
  return options;
}

Simulator start_simulator(const PlanRequest& request, const PlanCallbacks& callbacks) {
  try {
    return Simulator(request.geometry, request.params, simulator_options(request, callbacks));
  } catch (const SettleInterrupted&) {
    throw PlanCancelled();
  }
}

namespace {
PlanCancelled cancelled_with_plan_so_far(const Simulator& sim, const PlanResult& result) {
  PlanResult so_far = result;
  so_far.final_state = sim.state();
  return PlanCancelled(std::move(so_far));
}
}  // namespace

void apply_planned(Simulator& sim, const Action& action, PlanResult& result, const PlanCallbacks& callbacks) {
  if (callbacks.cancelled && callbacks.cancelled()) throw cancelled_with_plan_so_far(sim, result);
  try {
    sim.apply(action);
  } catch (const SettleInterrupted&) {
    throw cancelled_with_plan_so_far(sim, result);
  }
  result.steps.push_back(action);
  if (callbacks.snapshot) callbacks.snapshot(sim.state());
}

bool try_planned(Simulator& sim, const Action& action, PlanResult& result, const PlanCallbacks& callbacks) {
  const auto start = std::chrono::steady_clock::now();
  const auto seconds = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); };
  try {
    apply_planned(sim, action, result, callbacks);
    result.settle_seconds += seconds();
    return true;
  } catch (const NoEquilibrium& e) {
    result.refused.push_back({action, e.what(), int(result.steps.size())});
    result.refused_seconds += seconds();
    return false;
  }
}

PlanCheckpoint plan_checkpoint(const Simulator& sim, const PlanResult& result) {
  return {sim.checkpoint(), result.steps.size()};
}

void rewind_plan(Simulator& sim, PlanResult& result, const PlanCheckpoint& checkpoint) {
  sim.rewind(checkpoint.simulator);
  result.steps.resize(std::min(result.steps.size(), checkpoint.steps));
}

bool pin_reached_nodes(Simulator& sim, const Eigen::Matrix3Xd& goal_x, Reach reach, PlanResult& result,
                       const PlanCallbacks& callbacks) {
  const Mesh& mesh = sim.mesh();
  bool all_pinned = true;
  for (int a = 1; a < mesh.rows(); ++a)
    for (int b = 1; b < mesh.cols(); ++b) {
      if (sim.state().pinned(mesh, a, b)) continue;
      const int point = mesh.node_point(a, b);
      const double z = sim.state().x(2, point), goal = goal_x(2, point);
      const bool reached = reach == Reach::kFromBelow ? z >= goal : z <= goal;
      if (!(reached && try_planned(sim, Action::pin(a, b), result, callbacks))) all_pinned = false;
    }
  return all_pinned;
}

bool jam_reached_cells(Simulator& sim, const Eigen::MatrixXd& goal_curvature, Reach reach, PlanResult& result,
                       const PlanCallbacks& callbacks) {
  const Mesh& mesh = sim.mesh();
  bool all_jammed = true;
  for (int r = 0; r < mesh.rows(); ++r)
    for (int c = 0; c < mesh.cols(); ++c) {
      if (sim.state().jammed(mesh, r, c)) continue;
      const double k = cell_curvature(mesh, sim.state().x, r, c);
      const bool reached = reach == Reach::kFromBelow ? k >= goal_curvature(r, c) : k <= goal_curvature(r, c);
      if (!(reached && try_planned(sim, Action::jam(r, c), result, callbacks))) all_jammed = false;
    }
  return all_jammed;
}

bool every_cell_jammed(const Mesh& mesh, const DeviceState& state) {
  for (int r = 0; r < mesh.rows(); ++r)
    for (int c = 0; c < mesh.cols(); ++c)
      if (!state.jammed(mesh, r, c)) return false;
  return true;
}

bool is_free_net(const Mesh& mesh, const DeviceState& state) {
  for (int r = 0; r < mesh.rows(); ++r)
    for (int c = 0; c < mesh.cols(); ++c)
      if (state.jammed(mesh, r, c)) return false;
  for (int a = 1; a < mesh.rows(); ++a)
    for (int b = 1; b < mesh.cols(); ++b)
      if (state.pinned(mesh, a, b)) return false;
  return true;
}

Eigen::Matrix3Xd goal_positions(const Mesh& mesh, const Eigen::MatrixXd& goal_mm, double scale) {
  Eigen::Matrix3Xd goal_x = mesh.rest_positions();
  for (int i = 0; i < mesh.point_rows(); ++i)
    for (int j = 0; j < mesh.point_cols(); ++j) goal_x(2, mesh.index(i, j)) = scale * goal_mm(i, j) / 1000.0;
  return goal_x;
}

double plan_score(const PlanRequest& request, const Mesh& mesh, const DeviceState& state) {
  const Eigen::MatrixXd heights_mm = point_heights(mesh, state.x) * 1000.0;
  if (request.scoring == PlanScoring::kHeightError || request.goal_image.size() == 0)
    return mesh_point_score(request, heights_mm);
  // Mesh row i runs along +y; the image's row 0 is its top.
  return correlate_with_goal(request.goal_image, heights_mm.colwise().reverse()).value.value_or(-INFINITY);
}

double mesh_point_score(const PlanRequest& request, const Eigen::MatrixXd& heights_mm) {
  if (request.scoring == PlanScoring::kCorrelation)
    return correlate(request.goal_mm, heights_mm).value.value_or(-INFINITY);
  const Eigen::ArrayXXd error = (heights_mm - request.goal_mm).array();
  const Eigen::Index finite = error.isFinite().count();
  if (finite == 0) return -INFINITY;
  return -std::sqrt(error.isFinite().select(error.square(), 0.0).sum() / static_cast<double>(finite));
}

double mesh_point_score(const PlanRequest& request, const Mesh& mesh, const DeviceState& state) {
  return mesh_point_score(request, point_heights(mesh, state.x) * 1000.0);
}

double plan_max_pressure(double option_pa, const SurfaceParameters& params) {
  return option_pa > 0.0 ? std::min(option_pa, params.max_pressure_pa) : params.max_pressure_pa;
}

}  // namespace hj
