// Simulator::checkpoint and rewind: a trial action taken back leaves the
// simulator as if it had never been applied, so a plan without it replays.
#include <gtest/gtest.h>

#include <stdexcept>

#include "sim/simulator.h"

namespace hj {
namespace {

TEST(Rewind, ATrialTakenBackLeavesNoTraceInWhatFollows) {
  const ArrayGeometry g{3, 4, 0.038, 4};
  const SurfaceParameters params = SurfaceParameters::paper_defaults(g);
  Simulator planned(g, params), replayed(g, params);
  for (Simulator* sim : {&planned, &replayed}) {
    sim->apply(Action::set_pressure(1200.0));
    sim->apply(Action::jam(1, 1));
    sim->apply(Action::pin(1, 2));
  }
  const Simulator::Checkpoint before = planned.checkpoint();
  planned.apply(Action::set_pressure(400.0));  // a trial too far
  ASSERT_GT((planned.state().x - before.state.x).cwiseAbs().maxCoeff(), 1e-3);
  planned.rewind(before);
  EXPECT_EQ(planned.state().pressure_pa, 1200.0);
  EXPECT_EQ((planned.state().x - before.state.x).cwiseAbs().maxCoeff(), 0.0);

  planned.apply(Action::set_pressure(1000.0));
  replayed.apply(Action::set_pressure(1000.0));
  EXPECT_EQ((planned.state().x - replayed.state().x).cwiseAbs().maxCoeff(), 0.0);
}

TEST(Rewind, ACheckpointOfAnotherMeshIsRefused) {
  const ArrayGeometry small{2, 3, 0.038, 4}, large{3, 4, 0.038, 4};
  Simulator a(small, SurfaceParameters::paper_defaults(small)), b(large, SurfaceParameters::paper_defaults(large));
  EXPECT_THROW(b.rewind(a.checkpoint()), std::invalid_argument);
}

}  // namespace
}  // namespace hj
