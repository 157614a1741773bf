// A planner's settles through folded meshes (sim/dead_end_watch.h): a flow
// that wanders in place or cycles on a folded sag is refused as a dead end before its
// step budget, and one that snaps through folded states into a dome still
// settles.
#include <gtest/gtest.h>

#include <string>

#include "planner_dead_ends.h"
#include "plan/planner.h"
#include "sim/simulator.h"

namespace hj {
namespace {

Simulator planner_simulator(const ArrayGeometry& g, const std::vector<Action>& steps) {
  const PlanRequest request{g, SurfaceParameters::paper_defaults(g), {}, {}, {}};
  Simulator sim(g, request.params, simulator_options(request, {}));
  for (const Action& a : steps) sim.apply(a);
  return sim;
}

TEST(PlannerDeadEnd, AFlowThatWandersOnAFoldedSagIsRefusedAsStalled) {
  Simulator sim = planner_simulator({9, 12, 0.038, 4}, testing::bunny_9x12_jammed_sag());
  const DeviceState before = sim.state();
  try {
    sim.apply(Action::set_pressure(250.0));
    FAIL() << "250 Pa settled";
  } catch (const NoEquilibrium& e) {
    EXPECT_NE(std::string(e.what()).find("the flow stalled on a folded mesh"), std::string::npos) << e.what();
  }
  EXPECT_EQ(sim.state().pressure_pa, before.pressure_pa);
  EXPECT_EQ((sim.state().x - before.x).cwiseAbs().maxCoeff(), 0.0);
}

// Before the watch knew cycles, this settle spent the planner's whole step
// budget (150 steps).
TEST(PlannerDeadEnd, AFlowThatCyclesOnAFoldedSagIsRefusedAsStalled) {
  Simulator sim = planner_simulator({9, 12, 0.038, 4}, testing::luxembourg_9x12_cycling_sag());
  try {
    sim.apply(Action::set_pressure(250.0));
    FAIL() << "250 Pa settled";
  } catch (const NoEquilibrium& e) {
    EXPECT_NE(std::string(e.what()).find("the flow stalled on a folded mesh"), std::string::npos) << e.what();
  }
}

TEST(PlannerDeadEnd, ASagThatSnapsThroughFoldedStatesIntoADomeSettles) {
  Simulator sim = planner_simulator({5, 7, 0.038, 4}, testing::volcano_5x7_jammed_sag());
  ASSERT_LT(sim.state().x.row(2).maxCoeff(), 0.001);  // a sag
  const SettleReport report = sim.apply(Action::set_pressure(350.0));
  EXPECT_TRUE(report.converged);
  EXPECT_LT(report.residual_n, 1e-9);
  EXPECT_GT(sim.state().x.row(2).maxCoeff(), 0.020);  // a dome, 30 mm high
}

}  // namespace
}  // namespace hj
