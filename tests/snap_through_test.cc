// The snap-through fallback (sim/implicit_flow.h) and the jam/pin settle
// skip (SimulatorOptions::skip_settle_after_jam_or_pin): a jammed sag that
// must snap up when the pressure rises, where the static solver alone finds
// no equilibrium, reaches the one the paper's explicit Euler reaches; the
// skip changes no result.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "expect_error.h"
#include "model/action.h"
#include "sim/effect_registry.h"
#include "sim/implicit_flow.h"
#include "sim/mesh_folds.h"
#include "sim/simulator.h"
#include "sim/static_solver.h"

namespace hj {
namespace {

using testing_support::expect_error;

// 4 x 6 array, every cell jammed in the rest sag, then 1 kPa: the jammed
// plates must turn from sagging to bulging (the centre goes from -52.9 mm
// to +61.0 mm). Within the budget here (150 steps, to keep the test fast)
// the static solver does not make it; with its default budget it may
// (TheStaticSolverGivesUpOnceItStalls says when).
const ArrayGeometry kSnapArray{4, 6, 0.038, 4};

SimulatorOptions snap_options(bool flow) {
  SimulatorOptions options;
  options.static_options.max_iterations = 150;
  options.flow_fallback = flow;
  options.fallback_max_steps = 0;  // no explicit fallback
  return options;
}

Simulator jammed_sag(SimulatorOptions options) {
  Simulator sim(kSnapArray, SurfaceParameters::paper_defaults(kSnapArray), std::move(options));
  for (int r = 0; r < kSnapArray.rows; ++r)
    for (int c = 0; c < kSnapArray.cols; ++c) sim.apply(Action::jam(r, c));
  return sim;
}

double centre_height(const Simulator& sim) {
  const Mesh& m = sim.mesh();
  return sim.state().x(2, m.index(m.point_rows() / 2, m.point_cols() / 2));
}

TEST(SnapThrough, StaticAloneFindsNoEquilibrium) {
  Simulator sim = jammed_sag(snap_options(false));
  const Eigen::Matrix3Xd before = sim.state().x;
  expect_error<std::runtime_error>([&] { sim.apply(Action::set_pressure(1000.0)); },
                                   {"no static equilibrium", "set_pressure 1 kPa"});
  EXPECT_EQ(sim.state().x, before);  // left as it was
}

// Where a settle gets nowhere (the model has no equilibrium there, e.g. a
// fold), the careful controls stop once the residual has not halved for
// stall_iterations, rather than spend their whole budget. Every step is
// capped at a millionth of the spacing here, so the residual cannot halve
// whatever the rounding: the jammed plates' snap itself is a settle the
// static solver may or may not make (no equilibrium after 2,040 steps with
// UMFPACK's rounding, the flow's equilibrium in 482 with the band LU's).
TEST(SnapThrough, TheStaticSolverGivesUpOnceItStalls) {
  const Simulator sim = jammed_sag(snap_options(false));
  DeviceState state = sim.state();
  state.pressure_pa = 1000.0;
  StaticSolverOptions options;  // the default budget
  options.max_step_fraction = options.fast_step_fraction = 1e-6;
  options.stall_iterations = 100;
  const SettleReport report = settle_static(sim.model(), state, options);
  EXPECT_FALSE(report.converged);
  EXPECT_GT(report.residual_n, 1e-3);
  // The fast control's budget, then the careful control, stopped one step
  // past stall_iterations.
  EXPECT_LE(report.iterations, options.fast_iterations + options.stall_iterations + 2);
  std::printf("gave up after %d steps (%.2f s), residual %.3g N\n", report.iterations, report.seconds,
              report.residual_n);
}

TEST(SnapThrough, FlowReachesTheEquilibriumOfExplicitEuler) {
  Simulator flow = jammed_sag(snap_options(true));
  EXPECT_LT(centre_height(flow), -0.050);  // sagging, jammed
  const SettleReport& report = flow.apply(Action::set_pressure(1000.0));
  ASSERT_TRUE(report.converged);
  EXPECT_LT(report.residual_n, 1e-9);
  EXPECT_GT(centre_height(flow), 0.060);  // snapped up

  SimulatorOptions reference;
  reference.solver = SolverKind::kExplicit;
  Simulator euler = jammed_sag(reference);
  euler.apply(Action::set_pressure(1000.0));
  const double largest = (flow.state().x - euler.state().x).colwise().norm().maxCoeff();
  EXPECT_LT(largest, 1e-5) << "flow and explicit Euler differ by " << largest * 1000 << " mm";
}

TEST(SnapThrough, FlowIsInterruptible) {
  const Mesh mesh(kSnapArray);
  const ForceModel model(mesh, SurfaceParameters::paper_defaults(kSnapArray), make_baseline_effects());
  DeviceState state = DeviceState::flat(mesh);  // far from equilibrium under gravity
  ImplicitFlowOptions options;
  options.interrupted = [] { return true; };
  EXPECT_THROW(settle_implicit_flow(model, state, options), SettleInterrupted);
}

TEST(SnapThrough, BadFlowOptionsAreNamed) {
  ImplicitFlowOptions options;
  options.max_step_fraction = -1.0;
  expect_error<std::invalid_argument>([&] { options.validate(); }, {"max_step_fraction"});
  options = {};
  options.force_tolerance_n = std::nan("");
  expect_error<std::invalid_argument>([&] { options.validate(); }, {"force_tolerance_n"});
  SimulatorOptions sim;
  sim.fallback_max_steps = -1;
  expect_error<std::invalid_argument>(
      [&] { Simulator(kSnapArray, SurfaceParameters::paper_defaults(kSnapArray), sim); }, {"fallback_max_steps"});
}

// A mixed sequence on the paper's 3 x 4 device, every action followed by a
// comparison of the two simulators' states.
TEST(JamPinSkip, ChangesNoResult) {
  const ArrayGeometry paper{3, 4, 0.038, 4};
  SimulatorOptions with_skip, without_skip;
  without_skip.skip_settle_after_jam_or_pin = false;
  Simulator a(paper, SurfaceParameters::paper_defaults(paper), with_skip);
  Simulator b(paper, SurfaceParameters::paper_defaults(paper), without_skip);
  const std::vector<Action> steps = {
      Action::set_pressure(200.0), Action::jam(0, 0), Action::jam(1, 1), Action::pin(1, 1),
      Action::set_pressure(800.0), Action::pin(2, 2), Action::jam(2, 3), Action::jam(1, 2),
      Action::set_pressure(1500.0), Action::unpin(1, 1), Action::jam(0, 3), Action::pin(1, 3),
      Action::unjam(1, 1), Action::set_pressure(600.0), Action::jam(2, 0), Action::pin(2, 1)};
  int skipped = 0;
  for (const Action& step : steps) {
    const SettleReport& ra = a.apply(step);
    b.apply(step);
    if ((step.op == Action::Op::kJam || step.op == Action::Op::kPin) && ra.iterations == 0) ++skipped;
    const double largest = (a.state().x - b.state().x).colwise().norm().maxCoeff();
    EXPECT_LT(largest, 1e-9) << "after " << step.describe();
  }
  EXPECT_EQ(skipped, 10);  // every jam and pin here starts at equilibrium
}

}  // namespace
}  // namespace hj

namespace hj {
namespace {

// A 2 x 2 mesh (p = 4) with one point pushed back past its x neighbour:
// the segment pair at it turns back, a fold; the flat mesh has none.
TEST(MeshFolds, FindsAFoldedPointAndNamesIt) {
  const Mesh mesh(ArrayGeometry{2, 2, 0.038, 4});
  Eigen::Matrix3Xd x = mesh.rest_positions();
  EXPECT_EQ(find_mesh_folds(mesh, x).count, 0);
  EXPECT_EQ(find_mesh_folds(mesh, x).describe(), "");
  // Point (3, 4) moves 1.5 h back along -x, to 2.5 h: the segment from
  // (3, 3) to it points along -x, the ones before and after along +x, so
  // the pairs at (3, 3) and (3, 4) turn back by 180 degrees; at (3, 5) both
  // point along +x. Along y the pair at (3, 4), (-1.5 h, h) then (1.5 h, h),
  // bends by 112.6 degrees: a third fold.
  const double h = mesh.spacing();
  x(0, mesh.index(3, 4)) -= 1.5 * h;
  const MeshFolds folds = find_mesh_folds(mesh, x);
  EXPECT_EQ(folds.count, 3);
  EXPECT_NEAR(folds.sharpest_deg, 180.0, 1e-6);
  EXPECT_EQ(folds.row, 3);
  EXPECT_TRUE(folds.col == 3 || folds.col == 4) << folds.col;
  EXPECT_EQ(folds.axis, 'x');
  EXPECT_EQ(folds.describe().rfind("the mesh is folded at 3 places, sharpest 180 degrees at point (3, ", 0), 0u)
      << folds.describe();
  // A bend of 60 degrees is no fold.
  x = mesh.rest_positions();
  x(2, mesh.index(3, 4)) += h * std::tan(M_PI / 6.0);  // each segment 30 degrees off: 60 at (3, 4)
  EXPECT_EQ(find_mesh_folds(mesh, x).count, 0);
}

}  // namespace
}  // namespace hj
