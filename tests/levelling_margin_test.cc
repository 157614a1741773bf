// PlanRequest::levelling_margin: a plan for a device takes no action where
// its sag may still be turning into a dome. algorithm2-levelled with a margin
// must carry the free net past it in one step, jam and pin only above it, end
// above it, and still replay to the surface it predicts; a margin outside its
// range is refused by name.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "plan/planner.h"

namespace hj {
namespace {

const ArrayGeometry kThreeByFour{3, 4, 0.038, 4};

Eigen::MatrixXd ridge(const Mesh& mesh) {
  Eigen::MatrixXd goal(mesh.point_rows(), mesh.point_cols());
  for (int i = 0; i < goal.rows(); ++i)
    for (int j = 0; j < goal.cols(); ++j)
      goal(i, j) = 30.0 * std::sin(M_PI * i / (goal.rows() - 1)) * std::sin(M_PI * j / (goal.cols() - 1)) *
                   (0.6 + 0.4 * std::cos(2.0 * M_PI * j / (goal.cols() - 1)));
  return goal;
}

TEST(LevellingMargin, LevelledPlanActsOnlyAboveTheMarginAndReplays) {
  const SurfaceParameters params = SurfaceParameters::paper_defaults(kThreeByFour);
  const Mesh mesh(kThreeByFour);
  PlanRequest request{kThreeByFour, params, ridge(mesh), {}, {}};
  request.levelling_margin = 1.5;
  const double act_from = 1.5 * params.levelling_pressure_pa(mesh);
  const PlanResult plan = make_planner("algorithm2-levelled")->plan(request);

  ASSERT_FALSE(plan.steps.empty());
  ASSERT_EQ(plan.steps.front().op, Action::Op::kSetPressure);
  EXPECT_GE(plan.steps.front().pressure_pa, act_from - 1e-9) << "the free net is carried past the margin at once";
  double pressure = 0.0;
  int actions = 0;
  for (const Action& a : plan.steps) {
    if (a.op == Action::Op::kSetPressure) {
      pressure = a.pressure_pa;
      EXPECT_GE(pressure, act_from - 1e-9) << a.describe();
      continue;
    }
    ++actions;
    EXPECT_GE(pressure, act_from - 1e-9) << a.describe() << " below the margin";
  }
  EXPECT_GT(actions, 0) << "the plan jams or pins something";

  Simulator replay(kThreeByFour, params);
  for (const Action& a : plan.steps) replay.apply(a);
  EXPECT_LT((replay.state().x - plan.final_state.x).cwiseAbs().maxCoeff(), 1e-5);
}

TEST(LevellingMargin, OutsideItsRangeIsRefusedByName) {
  const Mesh mesh(kThreeByFour);
  for (double margin : {0.5, 5.0, std::numeric_limits<double>::quiet_NaN()}) {
    PlanRequest request{kThreeByFour, SurfaceParameters::paper_defaults(kThreeByFour), ridge(mesh), {}, {}};
    request.levelling_margin = margin;
    try {
      make_planner("algorithm2-levelled")->plan(request);
      ADD_FAILURE() << "margin " << margin << " was accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("levelling margin"), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace hj
