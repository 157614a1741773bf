// algorithm2-refined (src/plan/algorithm2_refined.h): a search over Algorithm
// 2 variants must do at least as well as the search found on a bump, keep to
// the device's limits, and its steps (back-offs and the end-pressure scan
// included) must replay to the surface it predicts.
#include <gtest/gtest.h>

#include <cmath>

#include "metrics/correlation.h"
#include "plan/planner.h"
#include "sim/surface_measures.h"

namespace hj {
namespace {

const ArrayGeometry kTwoByTwo{2, 2, 0.038, 4};

Eigen::MatrixXd centred_bump(const Mesh& mesh) {
  Eigen::MatrixXd bump(mesh.point_rows(), mesh.point_cols());
  const double ci = 0.5 * (bump.rows() - 1), cj = 0.5 * (bump.cols() - 1), sigma = bump.rows() / 6.0;
  for (int i = 0; i < bump.rows(); ++i)
    for (int j = 0; j < bump.cols(); ++j)
      bump(i, j) = 30.0 * std::exp(-(std::pow(i - ci, 2) + std::pow(j - cj, 2)) / (2 * sigma * sigma));
  return bump;
}

TEST(Algorithm2Refined, BeatsAlgorithm2OnABumpAndItsStepsReplay) {
  const SurfaceParameters params = SurfaceParameters::paper_defaults(kTwoByTwo);
  const Mesh mesh(kTwoByTwo);
  const PlanRequest request{kTwoByTwo, params, centred_bump(mesh), {}, {}};
  const PlanResult plain = make_planner("algorithm2")->plan(request);
  const PlanResult refined = make_planner("algorithm2-refined")->plan(request);
  const auto r = [&](const DeviceState& s) { return *correlate(request.goal_mm, point_heights(mesh, s.x) * 1000.0).value; };
  EXPECT_GT(r(refined.final_state), r(plain.final_state));

  Simulator replay(kTwoByTwo, params);
  for (const Action& a : refined.steps) {
    EXPECT_NO_THROW(a.validate(mesh, params)) << a.describe();
    replay.apply(a);
  }
  EXPECT_LT((replay.state().x - refined.final_state.x).cwiseAbs().maxCoeff(), 1e-6);
}

}  // namespace
}  // namespace hj
