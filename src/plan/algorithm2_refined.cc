#include "plan/algorithm2_refined.h"

#include <cmath>
#include <cstdio>
#include <optional>
#include <stdexcept>

#include "sim/surface_measures.h"

namespace hj {

namespace {

struct Variant {
  double scale, increment_pa;
  bool jam_below_levelling;
  bool bisect_pins;
};

// Bisection of a pressure step that carries a free node past its target by
// more than max(kPinToleranceMm, kPinToleranceFraction * target relief):
// back to the previous pressure with half the step, down to kMinStepPa.
constexpr double kPinToleranceMm = 0.5;
constexpr double kPinToleranceFraction = 0.02;
constexpr double kMinStepPa = 1.0;
// Doublings of a refused step of a free net tried before halving it.
constexpr int kMaxJumps = 3;
// End pressures tried, as multiples of the levelling pressure, from high to low.
constexpr double kEndPressureFactors[] = {4.0, 3.0, 2.0, 1.5, 1.25, 1.1, 1.02};

// Algorithm 2 (algorithm2.cc) with the variant's knobs: targets scale * goal,
// and, unless jam_below_levelling, no jam while the pressure is below the
// levelling pressure.
PlanResult run_variant(const PlanRequest& request, const Variant& v, double p_max,
                       const PlanCallbacks& callbacks) {
  Simulator sim(request.geometry, request.params, simulator_options(request, callbacks));
  const Mesh& mesh = sim.mesh();
  const double p_level = request.params.levelling_pressure_pa(mesh);
  const Eigen::Matrix3Xd goal_x = goal_positions(mesh, request.goal_mm, v.scale);
  const Eigen::MatrixXd goal_curvature = cell_curvatures(mesh, goal_x);

  // A variant streams no snapshots (only the chosen one is sent); a pressure
  // step with no equilibrium is refused and handled as an overshoot.
  PlanCallbacks quiet;
  quiet.cancelled = callbacks.cancelled;
  PlanResult result;
  auto apply = [&](double pressure_pa) { return try_planned(sim, Action::set_pressure(pressure_pa), result, quiet); };
  const double tolerance_m =
      std::max(kPinToleranceMm, kPinToleranceFraction * v.scale * (request.goal_mm.maxCoeff() - request.goal_mm.minCoeff())) /
      1000.0;
  const auto overshoots = [&] {
    for (int a = 1; a < mesh.rows(); ++a)
      for (int b = 1; b < mesh.cols(); ++b) {
        const int point = mesh.node_point(a, b);
        if (!sim.state().pinned(mesh, a, b) && sim.state().x(2, point) > goal_x(2, point) + tolerance_m) return true;
      }
    return false;
  };
  // Jams (and, with a levelling margin, any action) from here up.
  const double act_from = v.jam_below_levelling ? 0.0 : request.levelling_margin * p_level;
  const bool carry_across = !v.jam_below_levelling && request.levelling_margin > 1.0;
  double previous = 0.0, step = v.increment_pa, carry_to = act_from;
  int jumps = 0;
  while (previous < p_max) {
    double pressure = std::min(previous + step, p_max);
    if (carry_across && pressure < carry_to && is_free_net(mesh, sim.state())) pressure = std::min(carry_to, p_max);
    const PlanCheckpoint before = plan_checkpoint(sim, result);
    if (!apply(pressure)) {
      // A free net folds only where it is slack, just past levelling on a
      // large array: more pressure tautens it. Anything jammed or pinned: smaller steps.
      if (is_free_net(mesh, sim.state()) && jumps < kMaxJumps && pressure < p_max) {
        if (carry_across && pressure >= carry_to) carry_to = pressure + step;
        step *= 2.0;
        ++jumps;
        continue;
      }
      if (step <= kMinStepPa) break;
      step /= 2.0;
      continue;
    }
    jumps = 0;
    if (v.bisect_pins && step > kMinStepPa && overshoots()) {  // taken back (plan_checkpoint)
      rewind_plan(sim, result, before);
      step /= 2.0;
      continue;
    }
    previous = pressure;
    const std::size_t steps_before = result.steps.size();
    const bool nodes_done = pin_reached_nodes(sim, goal_x, Reach::kFromBelow, result, quiet);
    const bool may_jam = pressure >= act_from;
    const bool cells_done = may_jam ? jam_reached_cells(sim, goal_curvature, Reach::kFromBelow, result, quiet)
                                    : every_cell_jammed(mesh, sim.state());
    if (nodes_done && cells_done) break;
    if (result.steps.size() > steps_before + 1) step = v.increment_pa;  // pinned or jammed: full steps again
  }
  // End pressure: with the pins and jams set, lower pressure lets the cells
  // between pins relax from the bulge that lifting the highest nodes needed.
  // Scan down towards the levelling pressure and end at the best one
  // (rewound to).
  const auto score = [&] { return mesh_point_score(request, mesh, sim.state()); };
  double best_r = score();
  PlanCheckpoint best = plan_checkpoint(sim, result);
  for (double f : kEndPressureFactors) {
    if (carry_across && f < request.levelling_margin) continue;
    const double p = f * p_level;
    if (p >= sim.state().pressure_pa || p > p_max) continue;
    if (!apply(p)) continue;
    if (const double r = score(); r > best_r) best_r = r, best = plan_checkpoint(sim, result);
  }
  rewind_plan(sim, result, best);
  result.final_state = sim.state();
  return result;
}

}  // namespace

void Algorithm2RefinedOptions::validate() const {
  if (increments_pa.empty() || height_scales.empty() || jam_below_levelling.empty())
    throw std::invalid_argument(
        "Algorithm2RefinedOptions.height_scales, increments_pa and jam_below_levelling must not be empty");
  for (double d : increments_pa)
    if (!(d > 0.0) || !std::isfinite(d))
      throw std::invalid_argument("Algorithm2RefinedOptions.increments_pa (Pa) must all be > 0");
  for (double s : height_scales)
    if (!(s > 0.0) || !std::isfinite(s))
      throw std::invalid_argument("Algorithm2RefinedOptions.height_scales must all be > 0");
  if (!(max_pressure_pa >= 0.0)) throw std::invalid_argument("Algorithm2RefinedOptions.max_pressure_pa (Pa) must be >= 0");
}

Algorithm2Refined::Algorithm2Refined(Algorithm2RefinedOptions options) : options_(std::move(options)) {
  options_.validate();
}

PlanResult Algorithm2Refined::plan(const PlanRequest& request, const PlanCallbacks& callbacks) const {
  const Mesh mesh(request.geometry);
  validate_plan_request(request, mesh);
  const double p_max = plan_max_pressure(options_.max_pressure_pa, request.params);
  std::vector<Variant> variants;
  for (double s : options_.height_scales)
    for (double d : options_.increments_pa)
      for (bool j : options_.jam_below_levelling)
        for (bool b : options_.bisect_pins) variants.push_back({s, d, j, b});

  std::optional<PlanResult> best;
  double best_r = -INFINITY;
  std::string last_error;
  for (std::size_t k = 0; k < variants.size(); ++k) {
    const Variant& v = variants[k];
    if (callbacks.progress) {
      char what[96];
      std::snprintf(what, sizeof what, "variant %zu/%zu: scale %g, %g Pa steps%s", k + 1, variants.size(), v.scale,
                    v.increment_pa, v.jam_below_levelling ? "" : ", jam above levelling");
      callbacks.progress(double(k) / double(variants.size()), what);
    }
    PlanResult candidate;
    try {
      candidate = run_variant(request, v, p_max, callbacks);
    } catch (const PlanCancelled&) {
      throw;
    } catch (const SettleInterrupted&) {
      throw PlanCancelled();
    } catch (const std::runtime_error& e) {
      last_error = e.what();  // no equilibrium on this path: the other variants may find one
      continue;
    }
    const double r = mesh_point_score(request, mesh, candidate.final_state);
    if (!best || r > best_r) best_r = r, best = std::move(candidate);
  }
  if (!best) throw std::runtime_error("algorithm2-refined: no variant reached equilibrium: " + last_error);
  if (callbacks.progress) callbacks.progress(1.0, "best variant chosen");
  if (callbacks.snapshot) callbacks.snapshot(best->final_state);
  return std::move(*best);
}

namespace {
const bool registered =
    (register_planner("algorithm2-refined", [] { return std::make_unique<Algorithm2Refined>(); }), true);
}  // namespace

}  // namespace hj
