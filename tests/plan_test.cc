// Algorithm 2 (paper section 5) on goals whose answers are known.
#include <gtest/gtest.h>

#include <cmath>

#include "metrics/correlation.h"
#include "plan/algorithm2.h"
#include "sim/surface_measures.h"

namespace hj {
namespace {

const ArrayGeometry kPaper{3, 4, 0.038, 4};

Eigen::MatrixXd heights_mm(const Mesh& mesh, const DeviceState& state) { return point_heights(mesh, state.x) * 1000.0; }

TEST(Algorithm2, MatchesAGoalTheDeviceMade) {
  const SurfaceParameters params = SurfaceParameters::paper_defaults(kPaper);
  Simulator device(kPaper, params);
  for (const Action& a : {Action::set_pressure(600), Action::set_pressure(310), Action::jam(0, 1), Action::pin(1, 2),
                          Action::set_pressure(1500)})
    device.apply(a);
  const PlanRequest request{kPaper, params, heights_mm(device.mesh(), device.state()), {}, {}};
  const PlanResult plan = make_planner("algorithm2")->plan(request);
  const Correlation c = correlate(request.goal_mm, heights_mm(device.mesh(), plan.final_state));
  ASSERT_TRUE(c.value.has_value()) << c.undefined_reason;
  EXPECT_GT(*c.value, 0.95);
}

TEST(Algorithm2, ReproducesASurfaceItMadeItself) {
  // Its own result is a goal it can reach by the same sweep: a fixed point.
  const SurfaceParameters params = SurfaceParameters::paper_defaults(kPaper);
  const Mesh mesh(kPaper);
  Eigen::MatrixXd bump(mesh.point_rows(), mesh.point_cols());
  for (int i = 0; i < bump.rows(); ++i)
    for (int j = 0; j < bump.cols(); ++j)
      bump(i, j) = 30.0 * std::exp(-(std::pow(i - 6.0, 2) + std::pow(j - 8.0, 2)) / 20.0);
  const auto planner = make_planner("algorithm2");
  const PlanResult first = planner->plan({kPaper, params, bump, {}});
  const Eigen::MatrixXd made = heights_mm(mesh, first.final_state);
  const PlanResult second = planner->plan({kPaper, params, made, {}});
  const Correlation c = correlate(made, heights_mm(mesh, second.final_state));
  ASSERT_TRUE(c.value.has_value());
  EXPECT_GT(*c.value, 0.99);
}

TEST(Algorithm2, StepsAreInTheSessionVocabularyAndRespectTheDevice) {
  const SurfaceParameters params = SurfaceParameters::paper_defaults(kPaper);
  const Mesh mesh(kPaper);
  const Eigen::MatrixXd goal = Eigen::MatrixXd::Constant(mesh.point_rows(), mesh.point_cols(), 10.0);
  const PlanResult plan = make_planner("algorithm2")->plan({kPaper, params, goal, {}});
  double last_pressure = 0.0;
  for (const Action& a : plan.steps) {
    EXPECT_NO_THROW(a.validate(mesh, params)) << a.describe();
    if (a.op == Action::Op::kSetPressure) {
      EXPECT_GT(a.pressure_pa, last_pressure);  // the sweep only rises
      last_pressure = a.pressure_pa;
    }
  }
  EXPECT_LE(last_pressure, params.max_pressure_pa);
}

TEST(Algorithm2, RejectsAGoalOfTheWrongShapeOrWithNaN) {
  const SurfaceParameters params = SurfaceParameters::paper_defaults(kPaper);
  const auto planner = make_planner("algorithm2");
  EXPECT_THROW(planner->plan({kPaper, params, Eigen::MatrixXd::Zero(5, 5), {}}), std::invalid_argument);
  Eigen::MatrixXd goal = Eigen::MatrixXd::Zero(13, 17);
  goal(3, 3) = NAN;
  EXPECT_THROW(planner->plan({kPaper, params, goal, {}}), std::invalid_argument);
  EXPECT_THROW(make_planner("genetic"), std::invalid_argument);
}

TEST(Algorithm2, CancellationStopsThePlan) {
  const SurfaceParameters params = SurfaceParameters::paper_defaults(kPaper);
  PlanCallbacks callbacks;
  int polls = 0;
  callbacks.cancelled = [&] { return ++polls > 3; };
  EXPECT_THROW(make_planner("algorithm2")->plan({kPaper, params, Eigen::MatrixXd::Constant(13, 17, 20.0), {}}, callbacks),
               PlanCancelled);
}

TEST(Algorithm2, CancellationStopsASettleMidway) {
  // The cancel is polled inside every settle, not only between actions: the
  // rest settle alone takes more than three solver steps, so the plan stops
  // before its first action (polled only between actions, three would run).
  const SurfaceParameters params = SurfaceParameters::paper_defaults(kPaper);
  PlanCallbacks callbacks;
  int polls = 0, snapshots = 0;
  callbacks.cancelled = [&] { return ++polls > 3; };
  callbacks.snapshot = [&](const DeviceState&) { ++snapshots; };
  EXPECT_THROW(make_planner("algorithm2")->plan({kPaper, params, Eigen::MatrixXd::Constant(13, 17, 20.0), {}}, callbacks),
               PlanCancelled);
  EXPECT_EQ(snapshots, 0);
  EXPECT_EQ(polls, 4);
}

TEST(Simulator, AnInterruptedActionLeavesTheStateAsItWas) {
  int polls = 0;
  bool armed = false;
  SimulatorOptions options;
  options.interrupted = [&] { return armed && ++polls > 2; };
  Simulator sim(kPaper, SurfaceParameters::paper_defaults(kPaper), options);
  const DeviceState before = sim.state();
  armed = true;
  EXPECT_THROW(sim.apply(Action::set_pressure(2000.0)), SettleInterrupted);
  EXPECT_EQ(sim.state().pressure_pa, before.pressure_pa);
  EXPECT_TRUE(sim.state().x == before.x);
}

}  // namespace
}  // namespace hj
