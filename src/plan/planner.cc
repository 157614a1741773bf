#include "plan/planner.h"

#include <algorithm>
#include <map>
#include <sstream>

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
}

SimulatorOptions simulator_options(const PlanRequest& request, const PlanCallbacks& callbacks) {
  SimulatorOptions options = request.simulator;
  if (callbacks.cancelled) options.interrupted = callbacks.cancelled;
  return options;
}

Simulator start_simulator(const PlanRequest& request, const PlanCallbacks& callbacks) {
  try {
    return Simulator(request.geometry, request.params, simulator_options(request, callbacks));
  } catch (const SettleInterrupted&) {
    throw PlanCancelled();
  }
}

void apply_planned(Simulator& sim, const Action& action, PlanResult& result, const PlanCallbacks& callbacks) {
  if (callbacks.cancelled && callbacks.cancelled()) throw PlanCancelled();
  try {
    sim.apply(action);
  } catch (const SettleInterrupted&) {
    throw PlanCancelled();
  }
  result.steps.push_back(action);
  if (callbacks.snapshot) callbacks.snapshot(sim.state());
}

double plan_max_pressure(double option_pa, const SurfaceParameters& params) {
  return option_pa > 0.0 ? std::min(option_pa, params.max_pressure_pa) : params.max_pressure_pa;
}

}  // namespace hj
