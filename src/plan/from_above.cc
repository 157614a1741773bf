#include "plan/from_above.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

#include "sim/surface_measures.h"

namespace hj {

namespace {

// End pressures tried after the descent, as multiples of the levelling
// pressure, in rising order.
constexpr double kEndPressureFactors[] = {0.0, 0.5, 0.8, 0.9, 1.02, 1.1, 1.25, 1.5, 2.0};

// The largest pressure decrement that takes no free node more than
// tolerance_m below its goal, each node's height extrapolated linearly from
// its fall over the last step (`z_before`, the heights dp_last higher);
// infinity where no free node is falling. Jams and pins since change the
// slopes, so it is a guess: a step that still goes too far is taken back.
double predicted_safe_decrement(const Mesh& mesh, const DeviceState& state, const Eigen::VectorXd& z_before,
                                double dp_last, const Eigen::Matrix3Xd& goal_x, double tolerance_m) {
  double safe = std::numeric_limits<double>::infinity();
  for (int a = 1; a < mesh.rows(); ++a)
    for (int b = 1; b < mesh.cols(); ++b) {
      if (state.pinned(mesh, a, b)) continue;
      const int point = mesh.node_point(a, b);
      const double fall_per_pa = (z_before(point) - state.x(2, point)) / dp_last;
      if (fall_per_pa > 0.0)
        safe = std::min(safe, (state.x(2, point) - goal_x(2, point) + tolerance_m) / fall_per_pa);
    }
  return safe;
}

}  // namespace

void FromAboveOptions::validate() const {
  auto positive = [](double v, const char* field) {
    if (!(v > 0.0) || !std::isfinite(v)) throw std::invalid_argument(std::string("FromAboveOptions.") + field + " must be > 0");
  };
  positive(decrement_pa, "decrement_pa (Pa)");
  positive(min_step_pa, "min_step_pa (Pa)");
  if (!(pin_tolerance_mm >= 0.0) || !std::isfinite(pin_tolerance_mm))
    throw std::invalid_argument("FromAboveOptions.pin_tolerance_mm (mm) must be >= 0");
  if (!(pin_tolerance_fraction >= 0.0 && pin_tolerance_fraction < 1.0))
    throw std::invalid_argument("FromAboveOptions.pin_tolerance_fraction must lie in [0, 1)");
  if (!(max_pressure_pa >= 0.0) || !std::isfinite(max_pressure_pa))
    throw std::invalid_argument("FromAboveOptions.max_pressure_pa (Pa) must be >= 0 (0: the device maximum)");
}

FromAbove::FromAbove(FromAboveOptions options) : options_(options) { options_.validate(); }

PlanResult FromAbove::plan(const PlanRequest& request, const PlanCallbacks& callbacks) const {
  validate_plan_request(request, Mesh(request.geometry));
  Simulator sim = start_simulator(request, callbacks);
  const Mesh& mesh = sim.mesh();
  const double p_max = plan_max_pressure(options_.max_pressure_pa, request.params);
  const double p_level = request.params.levelling_pressure_pa(mesh);
  // Below levelling the cells between pinned nodes sag, which brings the
  // nodes around a pinned summit down to goals under the straight line from
  // it to the clamped edge, so the descent goes on down to no pressure.
  const double p_floor = 0.0;

  // The goal as a surface on the mesh, for its node heights and curvatures.
  const Eigen::Matrix3Xd goal_x = goal_positions(mesh, request.goal_mm);
  const Eigen::MatrixXd goal_curvature = cell_curvatures(mesh, goal_x);
  const double tolerance_m =
      std::max(options_.pin_tolerance_mm,
               options_.pin_tolerance_fraction * (request.goal_mm.maxCoeff() - request.goal_mm.minCoeff())) /
      1000.0;

  // Every pressure step goes through try_planned: one with no equilibrium
  // is refused (result.refused) and the plan goes on from the state it had.
  PlanResult result;
  auto apply = [&](double pressure_pa) { return try_planned(sim, Action::set_pressure(pressure_pa), result, callbacks); };
  auto progress = [&](double fraction, double pressure_pa, const char* phase) {
    if (!callbacks.progress) return;
    char what[64];
    std::snprintf(what, sizeof what, "%s, pressure %.3f kPa", phase, pressure_pa / 1000.0);
    callbacks.progress(fraction, what);
  };
  const auto free_node_height_error = [&](auto&& predicate) {
    for (int a = 1; a < mesh.rows(); ++a)
      for (int b = 1; b < mesh.cols(); ++b) {
        const int point = mesh.node_point(a, b);
        if (!sim.state().pinned(mesh, a, b) && predicate(sim.state().x(2, point) - goal_x(2, point))) return true;
      }
    return false;
  };

  // Up: double the pressure from twice levelling until every node is at or
  // above its goal (the first step crosses levelling, from the mirror image
  // of the sag, see sim/levelling_crossing.h).
  double target = p_level;
  do {
    target = std::min(2.0 * target, p_max);
    apply(target);
    progress(0.1, target, "raising");
  } while (target < p_max && free_node_height_error([](double dz) { return dz < 0.0; }));

  // Down: pin nodes and jam cells as they come down to their goals. A step
  // with no equilibrium, or one that takes a free node too far below its
  // goal, is halved (down to min_step_pa; a refused one that small ends the descent).
  // A step too far is taken back by rewinding the simulator, not by raising
  // the pressure again: the plan (and the device) never makes it, and the
  // settle back up is not paid for.
  double pressure = sim.state().pressure_pa;
  const double top = pressure;
  double step = options_.decrement_pa;
  // The last step kept: the point heights before it, and its size (Pa).
  Eigen::VectorXd z_before;
  double last_step = 0.0;
  while (pressure > p_floor) {
    // Within the step as halved, short of where the nodes are predicted to
    // go too far (with a margin: the fall is not linear in the pressure).
    const double trial =
        last_step > 0.0
            ? std::clamp(0.8 * predicted_safe_decrement(mesh, sim.state(), z_before, last_step, goal_x, tolerance_m),
                         std::min(options_.min_step_pa, step), step)
            : step;
    const double next = std::max(pressure - trial, p_floor);
    const PlanCheckpoint before = plan_checkpoint(sim, result);
    if (!apply(next)) {
      if (trial <= options_.min_step_pa) break;
      step = trial / 2.0;
      continue;
    }
    if (trial > options_.min_step_pa && free_node_height_error([&](double dz) { return dz < -tolerance_m; })) {
      rewind_plan(sim, result, before);
      step = trial / 2.0;
      continue;
    }
    last_step = pressure - next;
    z_before = before.simulator.state.x.row(2).transpose();
    pressure = next;
    const std::size_t steps_before = result.steps.size();
    const bool nodes_done = pin_reached_nodes(sim, goal_x, Reach::kFromAbove, result, callbacks);
    const bool cells_done = jam_reached_cells(sim, goal_curvature, Reach::kFromAbove, result, callbacks);
    const bool all_done = nodes_done && cells_done;
    progress(0.1 + 0.8 * (top - pressure) / std::max(top - p_floor, 1e-9), pressure, "lowering");
    if (all_done) break;
    if (result.steps.size() > steps_before + 1) step = options_.decrement_pa;  // pinned or jammed: full steps again
  }

  // End pressure: with the pins and jams set, cells between pins sag below
  // levelling and bulge above it. From the pressure reached, step through
  // the end pressures downwards while the score improves, else upwards
  // while it improves (a hill climb), and end at the best (rewound to).
  const auto score = [&] { return mesh_point_score(request, mesh, sim.state()); };
  std::vector<double> below, above;
  for (double f : kEndPressureFactors) {
    const double p = f * p_level;
    if (p < pressure) below.insert(below.begin(), p);
    else if (p > pressure && p <= p_max) above.push_back(p);
  }
  double best_r = score();
  PlanCheckpoint best = plan_checkpoint(sim, result);
  for (const std::vector<double>* direction : {&below, &above}) {
    bool improved = false;
    for (double p : *direction) {
      if (!apply(p)) break;
      const double r = score();
      if (!(r > best_r)) break;
      best_r = r, best = plan_checkpoint(sim, result), improved = true;
    }
    rewind_plan(sim, result, best);
    if (improved) break;
  }
  progress(1.0, sim.state().pressure_pa, "done");
  result.final_state = sim.state();
  return result;
}

namespace {
const bool registered = (register_planner("from-above", [] { return std::make_unique<FromAbove>(); }), true);
}  // namespace

}  // namespace hj
