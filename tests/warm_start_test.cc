// A warm start (Simulator::apply with a start state, what a fit's replays
// under nearby parameters use) must not change what a jam or a pin at an
// equilibrium does: the state stays as it is, with no settle.
#include <gtest/gtest.h>

#include "sim/simulator.h"

namespace hj {
namespace {

const ArrayGeometry kPaper{3, 4, 0.038, 4};

// The settled state, and a start 2 mm above it (as if settled under a
// lighter membrane).
struct AtEquilibrium {
  Simulator sim{kPaper, SurfaceParameters::paper_defaults(kPaper)};
  Eigen::Matrix3Xd before, start;
  AtEquilibrium() {
    sim.apply(Action::set_pressure(1000.0));
    before = sim.state().x;
    start = before;
    start.row(2).array() += 0.002;
  }
};

TEST(WarmStart, AJamOrPinAtEquilibriumKeepsTheStateWhateverTheStart) {
  for (const Action& action : {Action::jam(1, 1), Action::pin(1, 1)}) {
    SCOPED_TRACE(action.describe());
    AtEquilibrium a;
    const SettleReport& r = a.sim.apply(action, a.start);
    EXPECT_TRUE(r.converged);
    EXPECT_EQ(r.iterations, 0);
    EXPECT_EQ((a.sim.state().x - a.before).cwiseAbs().maxCoeff(), 0.0);
  }
}

// The pressure step after it does use the start, and reaches the
// equilibrium a cold settle reaches.
TEST(WarmStart, APressureStepFromAStartReachesTheColdEquilibrium) {
  AtEquilibrium warm, cold;
  warm.sim.apply(Action::jam(1, 1), warm.start);
  cold.sim.apply(Action::jam(1, 1));
  Eigen::Matrix3Xd start = cold.sim.state().x;
  start.row(2).array() += 0.001;
  warm.sim.apply(Action::set_pressure(1500.0), start);
  cold.sim.apply(Action::set_pressure(1500.0));
  EXPECT_LT((warm.sim.state().x - cold.sim.state().x).cwiseAbs().maxCoeff(), 1e-8);
}

}  // namespace
}  // namespace hj
