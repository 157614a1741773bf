// The bounded Gauss-Newton step (calib/bounded_step.h) of the screening and
// the cross-validation folds: a component that would leave its bound is held
// there and the others are solved again, not merely clamped.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "calib/bounded_step.h"

namespace hj {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

TEST(BoundedStep, IsTheLeastSquaresStepWhereNoBoundIsReached) {
  Eigen::MatrixXd j(3, 2);
  j << 1, 0, 0, 1, 1, 1;
  const Eigen::VectorXd r = Eigen::Vector3d(-1, -2, -3);
  const Eigen::VectorXd d = bounded_gauss_newton_step(j, r, Eigen::Vector2d(-kInf, -kInf), Eigen::Vector2d(kInf, kInf));
  // Exact data x = 1, y = 2: r + J d = 0.
  EXPECT_NEAR(d[0], 1.0, 1e-5);
  EXPECT_NEAR(d[1], 2.0, 1e-5);
}

TEST(BoundedStep, HoldsAComponentAtItsBoundAndRefitsTheOthers) {
  // Two correlated columns: the free optimum is (1, 2); with the first held
  // at 0.5, the second must take up what it can of the rest.
  Eigen::MatrixXd j(3, 2);
  j << 1, 0, 0, 1, 1, 1;
  const Eigen::VectorXd r = Eigen::Vector3d(-1, -2, -3);
  const Eigen::VectorXd d = bounded_gauss_newton_step(j, r, Eigen::Vector2d(-kInf, -kInf), Eigen::Vector2d(0.5, kInf));
  EXPECT_DOUBLE_EQ(d[0], 0.5);
  // min (2 - y)^2 + (2.5 - y)^2: y = 2.25, not the clamped step's 2.
  EXPECT_NEAR(d[1], 2.25, 1e-5);
  // And it is the constrained minimum: no feasible neighbour is better.
  const auto cost = [&](double a, double b) { return (r + j * Eigen::Vector2d(a, b)).squaredNorm(); };
  for (double da : {-0.01, 0.0})
    for (double db : {-0.01, 0.0, 0.01}) EXPECT_LE(cost(d[0], d[1]), cost(d[0] + da, d[1] + db) + 1e-12);
}

}  // namespace
}  // namespace hj
