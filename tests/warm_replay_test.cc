// A fit replays each session many times under nearby parameters, each
// replay warm-started from the last one's settled states (replay_session).
// Under stiff jams, the last replay's absolute positions are far from
// equilibrium in force: the jammed cells keep this replay's bend angles.
// So a warm step starts from this replay's state moved as the last replay
// moved over the same step; it must reach the cold replay's equilibria, in
// fewer solver steps.
#include <gtest/gtest.h>

#include <fstream>

#include <limits>

#include "calib/dataset.h"
#include "calib/replay_tally.h"
#include "calib/residuals.h"
#include "calib/session.h"
#include "calib_synthetic.h"
#include "scratch_dir.h"

namespace hj {
namespace {

using nlohmann::json;
using testing_support::ScratchDir;

// demo-baseline's jammed-sweep, shortened: level from above, every cell
// jammed, then 0 kPa and a sweep up, a capture after each.
Session jammed_sweep(const std::filesystem::path& dir) {
  json steps = json::array({{{"op", "capture"}, {"frame", "f0.csv"}},
                            {{"op", "set_pressure"}, {"kpa", 0.59}},
                            {{"op", "set_pressure"}, {"kpa", 0.295}}});
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) steps.push_back({{"op", "jam"}, {"cell", {r, c}}});
  int frame = 1;
  for (double kpa : {0.0, 0.43, 0.86, 1.73}) {
    steps.push_back({{"op", "set_pressure"}, {"kpa", kpa}});
    std::string name = "f";
    name += std::to_string(frame++);
    steps.push_back({{"op", "capture"}, {"frame", name + ".csv"}});
  }
  std::ofstream(dir / "session.json") << testing_support::tiny_session_json("jammed", steps).dump();
  return read_session(dir / "session.json");
}

struct Replay {
  std::vector<PredictedCapture> captures;
  int solver_steps = 0;
};

Replay replay(const Session& session, const ModelParams& params, const ReplayTrace* warm, ReplayTrace* trace) {
  Replay out;
  const auto count = [&](int, int, const SessionStep& step, const SettleReport& settle) {
    if (step.kind == SessionStep::Kind::kAction) out.solver_steps += settle.iterations;
  };
  out.captures = replay_session(session, 4, params.surface, simulator_options(params, ReplayOptions{}), count, warm,
                                trace);
  return out;
}

TEST(WarmReplay, UnderStiffJamsAWarmReplayReachesTheColdEquilibriaInFewerSteps) {
  ScratchDir dir;
  const Session session = jammed_sweep(dir.path);
  ModelParams last = testing_support::true_tiny_baseline();
  last.surface.kappa_jam = 100.0;  // a fit's upper bound: the stiffest jams
  ReplayTrace trace;
  replay(session, last, nullptr, &trace);
  for (double factor : {1.01, 1.1}) {
    SCOPED_TRACE(factor);
    ModelParams next = last;
    next.surface.spring_k *= factor;
    const Replay cold = replay(session, next, nullptr, nullptr);
    const Replay warm = replay(session, next, &trace, nullptr);
    ASSERT_EQ(warm.captures.size(), cold.captures.size());
    for (size_t k = 0; k < cold.captures.size(); ++k) {
      const Eigen::ArrayXXd difference = (warm.captures[k].heights_mm - cold.captures[k].heights_mm).array().abs();
      EXPECT_LT(difference.isNaN().select(0.0, difference).maxCoeff(), 1e-4) << "capture " << k;
    }
    // Near Newton from a near start: a 1 % change costs at most half the
    // cold replay's steps (the last replay's absolute states: 83 of 147).
    if (factor < 1.05) EXPECT_LT(2 * warm.solver_steps, cold.solver_steps);
    else EXPECT_LT(warm.solver_steps, cold.solver_steps);
  }
}

// A dataset replayed warm from its own traces gives the same sum of squares,
// and the tally tells the cold replays from the warm ones (where the time goes).
TEST(WarmReplay, TheTallyCountsColdReplaysApart) {
  const Dataset d = select_sessions(
      read_dataset(std::filesystem::path(HJ_SHARED_DIR) / "data/sessions/demo-baseline"), {"jammed-sweep", "mixed-1"},
      true);
  ReplayOptions replay = fitting_replay({});
  ReplayTally tally;
  replay.tally = &tally;
  std::vector<ReplayTrace> traces;
  const double inf = std::numeric_limits<double>::infinity();
  const ModelParams truth = testing_support::true_tiny_baseline();
  const double cold = dataset_sum_of_squares(d, truth, replay, 1, inf, nullptr, &traces);
  ASSERT_EQ(traces.size(), 2u);
  const double warm = dataset_sum_of_squares(d, truth, replay, 1, inf, &traces);
  EXPECT_NEAR(warm, cold, 1e-9 * cold);
  for (const ReplayTally::Entry& e : tally.entries()) {
    SCOPED_TRACE(e.session);
    EXPECT_EQ(e.replays, 2);
    EXPECT_EQ(e.cold, 1);
    EXPECT_GT(e.cold_cpu_s, 0.0);
    EXPECT_LT(e.cold_cpu_s, e.cpu_s);
  }
}

}  // namespace
}  // namespace hj
