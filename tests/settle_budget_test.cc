// SimulatorOptions::max_settle_steps: a settle that needs more solver steps
// than its budget is an action with no equilibrium found (NoEquilibrium),
// the state is left as it was, and the next action gets a fresh budget.
#include <gtest/gtest.h>

#include <string>
#include <utility>

#include "model/action.h"
#include "model/parameters.h"
#include "sim/settle_report.h"
#include "sim/simulator.h"

namespace hj {
namespace {

const ArrayGeometry kPaper{3, 4, 0.038, 4};

Simulator budgeted(int steps) {
  SimulatorOptions options;
  options.max_settle_steps = steps;
  options.fallback_max_steps = 0;
  return Simulator(kPaper, SurfaceParameters::paper_defaults(kPaper), options);
}

TEST(SettleBudget, AnActionPastItHasNoEquilibriumAndKeepsTheState) {
  Simulator sim = budgeted(2);
  const Eigen::Matrix3Xd rest = sim.state().x;
  try {
    sim.apply(Action::set_pressure(2000.0));
    FAIL() << "a 2-step budget settled rest -> 2 kPa";
  } catch (const NoEquilibrium& e) {
    EXPECT_NE(std::string(e.what()).find("within 2 solver steps after set_pressure"), std::string::npos) << e.what();
  }
  EXPECT_EQ(sim.state().pressure_pa, 0.0);
  EXPECT_EQ((sim.state().x - rest).cwiseAbs().maxCoeff(), 0.0);
}

TEST(SettleBudget, EachActionHasItsOwnAndAMovedSimulatorKeepsIt) {
  Simulator first = budgeted(200);
  Simulator sim = std::move(first);
  for (double kpa : {0.5, 1.0, 1.5, 2.0}) {
    const SettleReport& report = sim.apply(Action::set_pressure(kpa * 1000.0));
    EXPECT_TRUE(report.converged) << kpa << " kPa";
  }
  EXPECT_THROW(budgeted(-1), std::invalid_argument);
}

}  // namespace
}  // namespace hj
