// Where a plan's error lies: each kind of shortfall the seed paper names,
// made on purpose, lands in its own place.
#include <gtest/gtest.h>

#include <cmath>

#include "expect_error.h"
#include "metrics/error_breakdown.h"

namespace hj {
namespace {

const Mesh kMesh({3, 4, 0.038, 4});

// A smooth dome over the whole array, 0 at the clamped edge, mm.
Eigen::MatrixXd dome(double height_mm) {
  Eigen::MatrixXd z(kMesh.point_rows(), kMesh.point_cols());
  for (int i = 0; i < z.rows(); ++i)
    for (int j = 0; j < z.cols(); ++j)
      z(i, j) = height_mm * std::sin(M_PI * i / (z.rows() - 1)) * std::sin(M_PI * j / (z.cols() - 1));
  return z;
}

double share(const ErrorBreakdown& b, const std::string& name) {
  for (const ErrorPlace& p : b.places)
    if (p.name == name) return p.error_share;
  ADD_FAILURE() << "no place " << name;
  return 0.0;
}

// The error of `goal` against `predicted` lies (nearly) all in `place`, and it dominates.
void expect_error_in(const Eigen::MatrixXd& goal, const Eigen::MatrixXd& predicted, const std::string& place) {
  const ErrorBreakdown b = error_breakdown(kMesh, goal, predicted);
  EXPECT_GT(share(b, place), 0.9);
  EXPECT_EQ(b.dominant(), place);
}

TEST(ErrorBreakdown, AGoalRaisedAtTheClampedEdgeIsAnEdgeError) {
  Eigen::MatrixXd goal = dome(20.0), predicted = goal;
  goal.row(1).array() += 8.0;  // a quarter cell from the border, where the surface is held down
  expect_error_in(goal, predicted, "clamped_edge");
}

TEST(ErrorBreakdown, APitInACellsMiddleIsAValleyBetweenNodes) {
  Eigen::MatrixXd goal = dome(20.0);
  const Eigen::MatrixXd predicted = goal;
  goal(6, 6) -= 10.0;  // the middle of cell (1, 1), half a cell from every node
  expect_error_in(goal, predicted, "valley_between_nodes");
}

TEST(ErrorBreakdown, APitOnANodeIsNotAValleyBetweenNodes) {
  Eigen::MatrixXd goal = dome(20.0);
  const Eigen::MatrixXd predicted = goal;
  goal(4, 8) -= 10.0;  // node (1, 2), which a pin can hold low
  EXPECT_LT(share(error_breakdown(kMesh, goal, predicted), "valley_between_nodes"), 0.1);
}

TEST(ErrorBreakdown, ASpikeSmallerThanACellIsSubCellDetail) {
  Eigen::MatrixXd goal = dome(20.0);
  const Eigen::MatrixXd predicted = goal;
  goal(5, 9) += 10.0;  // one point, off its cell's centre: no dome of the cell makes it
  expect_error_in(goal, predicted, "sub_cell_detail");
}

TEST(ErrorBreakdown, SharesAddUpAndAPerfectPlanHasNoError) {
  const Eigen::MatrixXd goal = dome(20.0);
  Eigen::MatrixXd predicted = 0.5 * goal;
  predicted.array() += 3.0;  // scale and offset are not errors: correlation ignores them
  const ErrorBreakdown b = error_breakdown(kMesh, goal, predicted);
  EXPECT_LT(b.rms_mm, 1e-9);
  double area = 0.0;
  for (const ErrorPlace& p : b.places) area += p.area_share;
  EXPECT_NEAR(area, 1.0, 1e-12);
}

TEST(ErrorBreakdown, RefusesAWrongShapeOrNaN) {
  const Eigen::MatrixXd goal = dome(20.0);
  using testing_support::expect_error;
  expect_error<std::invalid_argument>([&] { error_breakdown(kMesh, goal, Eigen::MatrixXd::Zero(3, 3)); },
                                      {"the predicted surface is 3 x 3", "13 x 17"});
  Eigen::MatrixXd nan_goal = goal;
  nan_goal(2, 2) = NAN;
  expect_error<std::invalid_argument>([&] { error_breakdown(kMesh, nan_goal, goal); },
                                      {"the goal holds non-finite heights"});
}

}  // namespace
}  // namespace hj
