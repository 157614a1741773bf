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
  Eigen::Matrix3Xd goal_x = mesh.rest_positions();
  for (int i = 0; i < mesh.point_rows(); ++i)
    for (int j = 0; j < mesh.point_cols(); ++j) goal_x(2, mesh.index(i, j)) = request.goal_mm(i, j) / 1000.0;
  const Eigen::MatrixXd goal_curvature = cell_curvatures(mesh, goal_x);

  PlanResult result;
  auto apply = [&](const Action& action) { apply_planned(sim, action, result, callbacks); };
  const int increments = static_cast<int>(std::ceil(p_max / options_.pressure_increment_pa - 1e-9));
  for (int n = 1; n <= increments; ++n) {
    const double pressure = std::min(n * options_.pressure_increment_pa, p_max);
    apply(Action::set_pressure(pressure));
    bool all_done = true;
    for (int a = 1; a < mesh.rows(); ++a)
      for (int b = 1; b < mesh.cols(); ++b) {
        if (sim.state().pinned(mesh, a, b)) continue;
        const int point = mesh.node_point(a, b);
        if (sim.state().x(2, point) >= goal_x(2, point))
          apply(Action::pin(a, b));
        else
          all_done = false;
      }
    for (int r = 0; r < mesh.rows(); ++r)
      for (int c = 0; c < mesh.cols(); ++c) {
        if (sim.state().jammed(mesh, r, c)) continue;
        if (cell_curvature(mesh, sim.state().x, r, c) >= goal_curvature(r, c))
          apply(Action::jam(r, c));
        else
          all_done = false;
      }
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
