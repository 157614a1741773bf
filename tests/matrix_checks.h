// Element-wise comparison of height maps for tests: the same shape, NaN
// exactly where the other is NaN, and values within `tolerance` (0: equal).
#pragma once

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <cmath>

namespace hj::testing_support {

inline void expect_same(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b, double tolerance = 0.0) {
  ASSERT_EQ(a.rows(), b.rows());
  ASSERT_EQ(a.cols(), b.cols());
  for (Eigen::Index r = 0; r < a.rows(); ++r)
    for (Eigen::Index c = 0; c < a.cols(); ++c) {
      if (std::isnan(a(r, c)))
        EXPECT_TRUE(std::isnan(b(r, c))) << r << "," << c;
      else
        EXPECT_NEAR(a(r, c), b(r, c), tolerance) << r << "," << c;
    }
}

}  // namespace hj::testing_support
