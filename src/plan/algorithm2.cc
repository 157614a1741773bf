// The seed paper's Algorithm 2: from rest, raise the chamber pressure in
// increments up to the maximum, settling after each; pin every node whose
// height reaches its goal height and jam every cell whose curvature (Eq. 11)
// reaches the goal cell's curvature; stop when everything is pinned and
// jammed or the pressure is at its maximum.
#include <cmath>

#include "plan/algorithm2.h"
#include "sim/surface_measures.h"

namespace hj {

Algorithm2::Algorithm2(Algorithm2Options options) : options_(options) {
  if (!(options_.pressure_increment_pa > 0.0) || !std::isfinite(options_.pressure_increment_pa))
    throw std::invalid_argument("Algorithm 2 option pressure_increment_pa (Pa) must be > 0");
  if (!(options_.max_pressure_pa >= 0.0) || std::isnan(options_.max_pressure_pa))
    throw std::invalid_argument("Algorithm 2 option max_pressure_pa (Pa) must be >= 0 (0: the device maximum)");
}

PlanResult Algorithm2::plan(const PlanRequest& request, const PlanCallbacks& callbacks) const {
  validate_plan_request(request, Mesh(request.geometry));
  Simulator sim = start_simulator(request, callbacks);
  const Mesh& mesh = sim.mesh();
  const double p_max = plan_max_pressure(options_.max_pressure_pa, request.params);

  // The goal as a surface on the mesh, for its node heights and curvatures.
  const Eigen::Matrix3Xd goal_x = goal_positions(mesh, request.goal_mm);
  const Eigen::MatrixXd goal_curvature = cell_curvatures(mesh, goal_x);

  // A pressure step with no equilibrium is refused (result.refused) and the
  // rise ends there: a larger step from the same jams folds the same way
  // (the 9 x 12 volcano refuses every one from 0.25 to 3.45 kPa, and over
  // the 11 shared goals x 16 sizes no plan kept a step after a refused one).
  PlanResult result;
  const int increments = static_cast<int>(std::ceil(p_max / options_.pressure_increment_pa - 1e-9));
  for (int n = 1; n <= increments; ++n) {
    const double pressure = std::min(n * options_.pressure_increment_pa, p_max);
    if (!try_planned(sim, Action::set_pressure(pressure), result, callbacks)) break;
    const bool nodes_done = pin_reached_nodes(sim, goal_x, Reach::kFromBelow, result, callbacks);
    const bool cells_done = jam_reached_cells(sim, goal_curvature, Reach::kFromBelow, result, callbacks);
    const bool all_done = nodes_done && cells_done;
    if (callbacks.progress)
      callbacks.progress(double(n) / increments, "pressure " + std::to_string(pressure / 1000.0).substr(0, 5) + " kPa");
    if (all_done) break;
  }
  result.final_state = sim.state();
  return result;
}

namespace {
const bool registered = (register_planner("algorithm2", [] { return std::make_unique<Algorithm2>(); }), true);
}  // namespace

}  // namespace hj
