// Plans that finish at every size (refused dead ends instead of failures),
// replay from rest to their predicted surface, and the portfolio planner,
// which is never worse than Algorithm 2 by the score it is judged on.
#include <gtest/gtest.h>

#include <cmath>

#include "plan/planner.h"
#include "plan/portfolio.h"
#include "shapes/goal_importer.h"
#include "shapes/resample.h"
#include "sim/mesh_folds.h"
#include "sim/surface_measures.h"

namespace hj {
namespace {

Eigen::MatrixXd heights_mm(const Mesh& mesh, const DeviceState& state) { return point_heights(mesh, state.x) * 1000.0; }

std::size_t occurrences(const std::string& text, const std::string& what) {
  std::size_t count = 0;
  for (std::size_t at = 0; (at = text.find(what, at)) != std::string::npos; at += what.size()) ++count;
  return count;
}

// The plan's steps replayed from rest, as `hapticjam simulate` does: the
// largest distance of a point from the plan's predicted surface, m.
double replay_gap_m(const PlanRequest& request, const PlanResult& plan) {
  Simulator replay(request.geometry, request.params);
  for (const Action& a : plan.steps) replay.apply(a);
  return (replay.state().x - plan.final_state.x).cwiseAbs().maxCoeff();
}

// A surface the device itself made (above levelling, one jam, one pin), so
// a good planner can match it.
Eigen::MatrixXd device_made_goal(const ArrayGeometry& g) {
  Simulator device(g, SurfaceParameters::paper_defaults(g));
  for (const Action& a : {Action::set_pressure(1200), Action::jam(g.rows / 2, g.cols / 3), Action::pin(g.rows / 2, g.cols / 2),
                          Action::set_pressure(800)})
    device.apply(a);
  return heights_mm(device.mesh(), device.state());
}

void expect_matches_device_made_goal(const ArrayGeometry& g) {
  const PlanRequest request{g, SurfaceParameters::paper_defaults(g), device_made_goal(g), {}, {}};
  // What the strategies can reach, so no time budget: the strategy that
  // matches these goals can take longer than 5 x Algorithm 2's time.
  PortfolioOptions unlimited;
  unlimited.max_time_ratio = 0.0;
  const PlanResult plan = Portfolio(unlimited).plan(request);
  const Mesh mesh(g);
  EXPECT_GT(plan_score(request, mesh, plan.final_state), 0.95) << plan.note;
  EXPECT_LT(replay_gap_m(request, plan), 1e-5);
}

TEST(Portfolio, MatchesADeviceMadeGoalAt6x8) { expect_matches_device_made_goal({6, 8, 0.038, 4}); }
TEST(Portfolio, MatchesADeviceMadeGoalAt9x12) { expect_matches_device_made_goal({9, 12, 0.038, 4}); }

// The shared volcano DEM at the array's default relief, scored against its image.
PlanRequest volcano_request(const ArrayGeometry& g) {
  const HeightMap volcano = import_goal(HJ_SHARED_DIR "/data/dem/volcano_maunga_whau.csv");
  return {g, SurfaceParameters::paper_defaults(g), resample_to_mesh(volcano, Mesh(g)), {}, volcano.z};
}

TEST(Portfolio, IsNeverBelowAlgorithm2AndSaysWhatItChose) {
  const ArrayGeometry g{3, 4, 0.038, 4};
  const Mesh mesh(g);
  const PlanRequest request = volcano_request(g);
  const PlanResult paper = make_planner("algorithm2")->plan(request);
  int snapshots = 0;
  PlanCallbacks callbacks;
  callbacks.snapshot = [&](const DeviceState&) { ++snapshots; };
  const PlanResult best = make_planner("portfolio")->plan(request, callbacks);
  EXPECT_GE(plan_score(request, mesh, best.final_state), plan_score(request, mesh, paper.final_state));
  EXPECT_NE(best.note.find("chose "), std::string::npos) << best.note;
  EXPECT_NE(best.note.find("algorithm2"), std::string::npos) << best.note;
  EXPECT_GT(snapshots, 5);  // Algorithm 2's, streamed as it runs, then the chosen one
  EXPECT_LT(replay_gap_m(request, best), 1e-5);
}

TEST(PlanScore, HeightErrorSeesTheScaleThatCorrelationDoesNot) {
  const ArrayGeometry g{3, 4, 0.038, 4};
  PlanRequest request{g, SurfaceParameters::paper_defaults(g), device_made_goal(g), {}, {}};
  const Eigen::MatrixXd twice = 2.0 * request.goal_mm;
  EXPECT_NEAR(mesh_point_score(request, twice), 1.0, 1e-12);
  request.scoring = PlanScoring::kHeightError;
  EXPECT_EQ(mesh_point_score(request, request.goal_mm), 0.0);
  const double rms_goal = std::sqrt(request.goal_mm.array().square().mean());
  EXPECT_NEAR(mesh_point_score(request, twice), -rms_goal, 1e-9);
  EXPECT_GT(mesh_point_score(request, request.goal_mm.array() + 1.0), mesh_point_score(request, twice));
}

// A goal in absolute millimetres: the portfolio keeps the plan whose
// heights are closest, and is never farther than Algorithm 2's.
TEST(Portfolio, ChoosesByHeightsForAGoalInMillimetres) {
  const ArrayGeometry g{3, 4, 0.038, 4};
  const Mesh mesh(g);
  PlanRequest request{g, SurfaceParameters::paper_defaults(g), device_made_goal(g), {}, {},
                      PlanScoring::kHeightError};
  PortfolioOptions unlimited;
  unlimited.max_time_ratio = 0.0;
  const PlanResult best = Portfolio(unlimited).plan(request);
  const PlanResult paper = make_planner("algorithm2")->plan(request);
  const double best_score = plan_score(request, mesh, best.final_state);
  EXPECT_GE(best_score, plan_score(request, mesh, paper.final_state)) << best.note;
  EXPECT_LT(-best_score, 0.1 * (request.goal_mm.maxCoeff() - request.goal_mm.minCoeff())) << best.note;
  EXPECT_LT(replay_gap_m(request, best), 1e-5);
}

TEST(Portfolio, StopsTheOtherStrategiesAtItsTimeBudget) {
  // One thread runs Algorithm 2 first; a budget of a tiny fraction of its
  // time is spent before any other strategy's turn, so none is started.
  const ArrayGeometry g{2, 3, 0.038, 4};
  const PlanRequest request = volcano_request(g);
  PortfolioOptions options;
  options.threads = 1;
  options.max_time_ratio = 1e-9;
  const PlanResult best = Portfolio(options).plan(request);
  const PlanResult paper = make_planner("algorithm2")->plan(request);
  EXPECT_EQ(best.note.rfind("chose algorithm2;", 0), 0u) << best.note;
  EXPECT_EQ(occurrences(best.note, "not started"), Portfolio::strategies().size() - 1) << best.note;
  EXPECT_EQ(best.steps.size(), paper.steps.size());
  EXPECT_LT((best.final_state.x - paper.final_state.x).cwiseAbs().maxCoeff(), 1e-9);
}

// A planner stopped in the middle hands back its plan so far, and that
// plan replays from rest to the state it reports, whenever it was stopped.
TEST(Portfolio, AStoppedStrategyHandsBackAPlanThatReplays) {
  const PlanRequest request = volcano_request({3, 4, 0.038, 4});
  // Stopped while the rest state settles, a planner has no plan yet.
  int rest_polls = 0;
  SimulatorOptions counting = simulator_options(request, {});
  counting.interrupted = [&] { return ++rest_polls < 0; };
  Simulator(request.geometry, request.params, counting);
  int all_polls = 0;
  PlanCallbacks counted;
  counted.cancelled = [&] { return ++all_polls < 0; };
  make_planner("from-above")->plan(request, counted);
  for (double fraction : {0.0, 0.2, 0.5, 0.8, 0.95}) {
    const int polls_allowed = rest_polls + int(fraction * (all_polls - rest_polls));
    int polls = 0;
    PlanCallbacks callbacks;
    callbacks.cancelled = [&] { return ++polls > polls_allowed; };
    try {
      make_planner("from-above")->plan(request, callbacks);
      ADD_FAILURE() << "from-above finished within " << polls_allowed << " polls";
    } catch (const PlanCancelled& stopped) {
      ASSERT_NE(stopped.partial(), nullptr) << polls_allowed;
      EXPECT_LT(replay_gap_m(request, *stopped.partial()), 1e-5) << polls_allowed;
    }
  }
}

TEST(Portfolio, RefusesABadTimeBudget) {
  for (double ratio : {-1.0, std::nan(""), double(INFINITY)}) {
    PortfolioOptions options;
    options.max_time_ratio = ratio;
    EXPECT_THROW(options.validate(), std::invalid_argument) << ratio;
  }
  PortfolioOptions options;
  options.min_budget_s = -1.0;
  EXPECT_THROW(options.validate(), std::invalid_argument);
  for (double cap : {-1.0, std::nan(""), double(INFINITY)}) {
    PortfolioOptions capped;
    capped.max_seconds = cap;
    EXPECT_THROW(capped.validate(), std::invalid_argument) << cap;
  }
}

TEST(Portfolio, NoStrategyRunsPastTheCapInSeconds) {
  // No ratio limit, but a cap Algorithm 2 alone already passes: the others
  // are not started, and the plan is Algorithm 2's.
  const PlanRequest request = volcano_request({2, 3, 0.038, 4});
  PortfolioOptions options;
  options.max_time_ratio = 0.0;
  options.max_seconds = 1e-9;
  const PlanResult best = Portfolio(options).plan(request);
  EXPECT_EQ(best.note.rfind("chose algorithm2;", 0), 0u) << best.note;
  EXPECT_EQ(occurrences(best.note, "not started"), Portfolio::strategies().size() - 1) << best.note;
}

TEST(RefusedActions, ADeadEndIsRecordedAndThePlanFinishes) {
  // The volcano at 5 x 8 from rest: Algorithm 2 jams cells in the 50 Pa
  // sag, and raising the pressure past them folds the net (a dead end of
  // the model, not of a solver budget); those steps are refused.
  const ArrayGeometry g{5, 8, 0.038, 4};
  const Mesh mesh(g);
  const PlanRequest request = volcano_request(g);
  const PlanResult plan = make_planner("algorithm2")->plan(request);
  ASSERT_FALSE(plan.refused.empty());
  for (const RefusedAction& r : plan.refused) {
    EXPECT_EQ(r.action.op, Action::Op::kSetPressure) << r.action.describe();
    EXPECT_FALSE(r.reason.empty());
    EXPECT_LE(r.after_step, int(plan.steps.size()));
  }
  EXPECT_FALSE(find_mesh_folds(mesh, plan.final_state.x).sharpest_deg > SimulatorOptions{}.refuse_fold_deg);
  EXPECT_LT(replay_gap_m(request, plan), 1e-5);
}

}  // namespace
}  // namespace hj
