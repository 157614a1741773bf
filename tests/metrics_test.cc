// The goal metrics: the correlation coefficient of Stanley & Okamura 2015
// Eq. 12 with bicubic upscaling, and the Laplace predictor of section 5.4
// (kernel, mean of the inverted filtered image, the line fit of Table 2).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <vector>

#include <Eigen/Core>  // before OpenCV's Eigen adapter, which needs it
#include <opencv2/core/eigen.hpp>
#include <opencv2/imgproc.hpp>

#include "metrics/correlation.h"
#include "metrics/laplace_predictor.h"

namespace hj {
namespace {

const double kNaN = std::numeric_limits<double>::quiet_NaN();

// (rows x cols) smooth bump, in [0, 1]: a sum of two Gaussians.
Eigen::MatrixXd smooth_goal(int rows, int cols) {
  Eigen::MatrixXd g(rows, cols);
  for (int i = 0; i < rows; ++i)
    for (int j = 0; j < cols; ++j) {
      const double u = (i + 0.5) / rows, v = (j + 0.5) / cols;
      g(i, j) = std::exp(-((u - 0.4) * (u - 0.4) + (v - 0.35) * (v - 0.35)) / 0.05) +
                0.5 * std::exp(-((u - 0.7) * (u - 0.7) + (v - 0.75) * (v - 0.75)) / 0.02);
    }
  return g;
}

// (rows x cols) paraboloid z = 1 - r^2, r the distance from the centre, 1 at the rim.
Eigen::MatrixXd paraboloid(int rows, int cols) {
  Eigen::MatrixXd g(rows, cols);
  for (int i = 0; i < rows; ++i)
    for (int j = 0; j < cols; ++j) {
      const double u = 2.0 * (i + 0.5) / rows - 1.0, v = 2.0 * (j + 0.5) / cols - 1.0;
      g(i, j) = 1.0 - 0.5 * (u * u + v * v);
    }
  return g;
}

Eigen::MatrixXd checkerboard(int rows, int cols) {
  Eigen::MatrixXd g(rows, cols);
  for (int i = 0; i < rows; ++i)
    for (int j = 0; j < cols; ++j) g(i, j) = (i + j) % 2;
  return g;
}

// ---- correlate (Eq. 12)

TEST(MetricsCorrelate, MatrixWithItselfIsOne) {
  const Eigen::MatrixXd m = smooth_goal(9, 11);
  const Correlation c = correlate(m, m);
  ASSERT_TRUE(c.value.has_value()) << c.undefined_reason;
  EXPECT_NEAR(*c.value, 1.0, 1e-12);
  EXPECT_EQ(c.samples, 99);
}

TEST(MetricsCorrelate, MatrixWithItsNegationIsMinusOne) {
  const Eigen::MatrixXd m = smooth_goal(9, 11);
  const Correlation c = correlate(m, -m);
  ASSERT_TRUE(c.value.has_value()) << c.undefined_reason;
  EXPECT_NEAR(*c.value, -1.0, 1e-12);
}

TEST(MetricsCorrelate, InvariantUnderPositiveAffineMap) {
  const Eigen::MatrixXd m = smooth_goal(9, 11);
  const Eigen::MatrixXd mapped = (37.5 * m).array() + 1.0e3;  // e.g. a height in mm plus an offset
  const Correlation c = correlate(m, mapped);
  ASSERT_TRUE(c.value.has_value()) << c.undefined_reason;
  EXPECT_NEAR(*c.value, 1.0, 1e-12);
}

TEST(MetricsCorrelate, HandComputedTwoByThree) {
  // Both means 3.5; sum dA dB = 15.5, sum dA^2 = sum dB^2 = 17.5, so r = 31/35.
  Eigen::MatrixXd a(2, 3), b(2, 3);
  a << 1, 2, 3, 4, 5, 6;
  b << 1, 3, 2, 5, 4, 6;
  const Correlation c = correlate(a, b);
  ASSERT_TRUE(c.value.has_value()) << c.undefined_reason;
  EXPECT_NEAR(*c.value, 31.0 / 35.0, 1e-14);
  EXPECT_EQ(c.samples, 6);
}

TEST(MetricsCorrelate, NaNSamplesAreIgnoredInBothInputs) {
  Eigen::MatrixXd a(2, 3), b(2, 3);
  a << kNaN, 2, 3, 4, 5, 6;
  b << 1e6, 3, 2, 5, 4, kNaN;  // 1e6 sits under a's NaN and must not count
  // The 4 pairs left: a = 2 3 4 5, b = 3 2 5 4, both of mean 3.5.
  Eigen::MatrixXd ra(1, 4), rb(1, 4);
  ra << 2, 3, 4, 5;
  rb << 3, 2, 5, 4;
  const Correlation c = correlate(a, b);
  const Correlation reference = correlate(ra, rb);
  ASSERT_TRUE(c.value.has_value()) << c.undefined_reason;
  EXPECT_EQ(c.samples, 4);
  EXPECT_NEAR(*c.value, *reference.value, 1e-14);
  EXPECT_NEAR(*c.value, 0.6, 1e-14);  // sum dA dB = 3, sum dA^2 = sum dB^2 = 5
}

TEST(MetricsCorrelate, FlatInputIsUndefinedWithAReason) {
  const Eigen::MatrixXd m = smooth_goal(5, 6);
  const Eigen::MatrixXd flat = Eigen::MatrixXd::Constant(5, 6, 0.1);
  for (const Correlation& c : {correlate(flat, m), correlate(m, flat)}) {
    EXPECT_FALSE(c.value.has_value());
    EXPECT_NE(c.undefined_reason.find("flat"), std::string::npos) << c.undefined_reason;
    EXPECT_EQ(c.samples, 30);
  }
}

TEST(MetricsCorrelate, FewerThanTwoValidSamplesIsUndefined) {
  Eigen::MatrixXd a(1, 3), b(1, 3);
  a << 1, kNaN, 3;
  b << 1, 2, kNaN;
  const Correlation c = correlate(a, b);
  EXPECT_FALSE(c.value.has_value());
  EXPECT_FALSE(c.undefined_reason.empty());
  EXPECT_EQ(c.samples, 1);
}

TEST(MetricsCorrelate, SizeMismatchThrowsNamingBothShapes) {
  try {
    correlate(Eigen::MatrixXd::Zero(2, 3), Eigen::MatrixXd::Zero(3, 2));
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("(2 x 3)"), std::string::npos) << what;
    EXPECT_NE(what.find("(3 x 2)"), std::string::npos) << what;
  }
}

// ---- upscale_bicubic

TEST(MetricsUpscale, OutputHasTheRequestedSize) {
  const Eigen::MatrixXd up = upscale_bicubic(smooth_goal(4, 5), 31, 47);
  EXPECT_EQ(up.rows(), 31);
  EXPECT_EQ(up.cols(), 47);
}

TEST(MetricsUpscale, ConstantStaysExactlyConstant) {
  const Eigen::MatrixXd up = upscale_bicubic(Eigen::MatrixXd::Constant(4, 5, 0.0123), 40, 53);
  EXPECT_TRUE((up.array() == 0.0123).all());
}

TEST(MetricsUpscale, LinearRampStaysARampInTheInterior) {
  // z = 0.3 i + 1.7 j on (6 x 8) samples, scaled by exactly 5 each way.
  const int rows = 6, cols = 8, scale = 5;
  Eigen::MatrixXd ramp(rows, cols);
  for (int i = 0; i < rows; ++i)
    for (int j = 0; j < cols; ++j) ramp(i, j) = 0.3 * i + 1.7 * j;
  const Eigen::MatrixXd up = upscale_bicubic(ramp, rows * scale, cols * scale);

  // Output (i, j) samples the input at s = (i + 0.5) / scale - 0.5 (pixel
  // centres); the interior is where all four cubic taps fall inside
  // (1 <= s < n - 2). There OpenCV's kernel (a = -0.75) bends the line by
  // 0.5 t (1 - t)(1 - 2 t) per unit step, t = s - floor(s), and meets it at
  // the samples (t = 0, every fifth output here).
  auto source = [&](int i) { return (i + 0.5) / scale - 0.5; };
  auto bend = [](double s) {
    const double t = s - std::floor(s);
    return 0.5 * t * (1.0 - t) * (1.0 - 2.0 * t);
  };
  int checked = 0;
  for (int i = 1; i < rows * scale; ++i)
    for (int j = 1; j < cols * scale; ++j) {
      const double si = source(i), sj = source(j);
      if (si < 1 || si >= rows - 2 || sj < 1 || sj >= cols - 2) continue;
      ++checked;
      const double line = 0.3 * si + 1.7 * sj;
      // OpenCV's weights are floats: ~1e-7 relative.
      EXPECT_NEAR(up(i, j), line + 0.3 * bend(si) + 1.7 * bend(sj), 1e-5) << i << ", " << j;
      EXPECT_LE(std::abs(up(i, j) - line), std::sqrt(3.0) / 36.0 * (0.3 + 1.7) + 1e-5);
      // It rises along both axes.
      EXPECT_GT(up(i, j), up(i - 1, j));
      EXPECT_GT(up(i, j), up(i, j - 1));
    }
  EXPECT_EQ(checked, 15 * 25);
  EXPECT_NEAR(up(12, 17), ramp(2, 3), 1e-5);  // s = (2, 3) exactly
}

// ---- correlate_with_goal

TEST(MetricsCorrelateWithGoal, GoalAgainstItsAreaDownsampledCopyIsHigh) {
  const Eigen::MatrixXd goal = smooth_goal(130, 170);
  cv::Mat goal_cv, small_cv;
  cv::eigen2cv(goal, goal_cv);
  cv::resize(goal_cv, small_cv, cv::Size(17, 13), 0.0, 0.0, cv::INTER_AREA);
  Eigen::MatrixXd small;
  cv::cv2eigen(small_cv, small);
  ASSERT_EQ(small.rows(), 13);
  ASSERT_EQ(small.cols(), 17);

  const Correlation c = correlate_with_goal(goal, small);
  ASSERT_TRUE(c.value.has_value()) << c.undefined_reason;
  EXPECT_GT(*c.value, 0.95);
  EXPECT_EQ(c.samples, 130 * 170);
}

TEST(MetricsCorrelateWithGoal, NaNGoalPixelsDoNotCount) {
  Eigen::MatrixXd goal = smooth_goal(40, 50);
  goal.block(0, 0, 10, 50).setConstant(kNaN);  // outside the shape
  const Correlation c = correlate_with_goal(goal, Eigen::MatrixXd(smooth_goal(8, 10)));
  ASSERT_TRUE(c.value.has_value()) << c.undefined_reason;
  EXPECT_EQ(c.samples, 30 * 50);
}

TEST(MetricsCorrelateWithGoal, FlatGoalOrPredictionIsUndefined) {
  const Eigen::MatrixXd flat_goal = Eigen::MatrixXd::Constant(40, 50, 2.0);
  const Correlation c = correlate_with_goal(flat_goal, smooth_goal(8, 10));
  EXPECT_FALSE(c.value.has_value());
  EXPECT_NE(c.undefined_reason.find("the goal is flat"), std::string::npos) << c.undefined_reason;

  const Correlation d = correlate_with_goal(smooth_goal(40, 50), Eigen::MatrixXd::Constant(8, 10, 0.01));
  EXPECT_FALSE(d.value.has_value());
  EXPECT_NE(d.undefined_reason.find("the prediction is flat"), std::string::npos) << d.undefined_reason;
}

TEST(MetricsCorrelateWithGoal, NonFinitePredictionThrows) {
  Eigen::MatrixXd predicted = smooth_goal(8, 10);
  predicted(3, 4) = kNaN;
  EXPECT_THROW(correlate_with_goal(smooth_goal(40, 50), predicted), std::invalid_argument);
}

// ---- Laplace predictor (section 5.4)

TEST(MetricsLaplace, KernelSumsToZeroAndMatchesFspecial) {
  for (double alpha : {0.0, 0.2, 1.0 / 3.0, 0.5, 1.0}) EXPECT_NEAR(laplacian_kernel(alpha).sum(), 0.0, 1e-14);

  // fspecial('laplacian', 0.2) = [1/6 2/3 1/6; 2/3 -10/3 2/3; 1/6 2/3 1/6].
  Eigen::Matrix3d expected;
  expected << 1.0 / 6, 2.0 / 3, 1.0 / 6,  //
      2.0 / 3, -10.0 / 3, 2.0 / 3,        //
      1.0 / 6, 2.0 / 3, 1.0 / 6;
  EXPECT_NEAR((laplacian_kernel(0.2) - expected).cwiseAbs().maxCoeff(), 0.0, 1e-14);
}

TEST(MetricsLaplace, KernelRejectsAlphaOutsideZeroOne) {
  EXPECT_THROW(laplacian_kernel(-0.1), std::invalid_argument);
  EXPECT_THROW(laplacian_kernel(1.1), std::invalid_argument);
  EXPECT_THROW(laplacian_kernel(kNaN), std::invalid_argument);
}

TEST(MetricsLaplace, SmoothParaboloidScoresAboveCheckerboard) {
  const double smooth = laplace_mean(paraboloid(60, 80));
  const double busy = laplace_mean(checkerboard(60, 80));
  EXPECT_GT(smooth, busy);
  EXPECT_GT(smooth, 0.9);
  EXPECT_LT(busy, 0.1);
  EXPECT_GE(busy, 0.0);
  EXPECT_LE(smooth, 1.0);
}

TEST(MetricsLaplace, FlatGoalGivesExactlyOne) {
  EXPECT_EQ(laplace_mean(Eigen::MatrixXd::Constant(20, 30, 7.0)), 1.0);
  EXPECT_EQ(laplace_mean(Eigen::MatrixXd::Zero(20, 30), 0.2), 1.0);
}

TEST(MetricsLaplace, RejectsEmptyOrAllNaNGoal) {
  EXPECT_THROW(laplace_mean(Eigen::MatrixXd(0, 0)), std::invalid_argument);
  EXPECT_THROW(laplace_mean(Eigen::MatrixXd::Constant(3, 3, kNaN)), std::invalid_argument);
}

// ---- fit_line (Table 2)

TEST(MetricsFitLine, RecoversAnExactLine) {
  const std::vector<double> x = {0.1, 0.5, 0.9, 1.3, 2.0, 3.7};
  std::vector<double> y;
  for (double xi : x) y.push_back(2.0 * xi + 1.0);
  const LinearFit fit = fit_line(x, y);
  EXPECT_NEAR(fit.slope, 2.0, 1e-12);
  EXPECT_NEAR(fit.intercept, 1.0, 1e-12);
  EXPECT_NEAR(fit.r2, 1.0, 1e-12);
  EXPECT_EQ(fit.n, 6);
}

// y = 2 x + 1 + noise, noise ~ N(0, sigma), drawn from the generator given.
std::vector<double> noisy_line(const std::vector<double>& x, double sigma, std::mt19937& rng) {
  std::normal_distribution<double> noise(0.0, sigma);
  std::vector<double> y;
  for (double xi : x) y.push_back(2.0 * xi + 1.0 + noise(rng));
  return y;
}

TEST(MetricsFitLine, NoiseLowersRSquared) {
  std::mt19937 rng(20150101);
  std::vector<double> x;
  for (int i = 0; i < 50; ++i) x.push_back(0.02 * i);
  const LinearFit fit = fit_line(x, noisy_line(x, 0.2, rng));
  EXPECT_LT(fit.r2, 1.0);
  EXPECT_GT(fit.r2, 0.5);
  EXPECT_NEAR(fit.slope, 2.0, 0.5);
  EXPECT_NEAR(fit.intercept, 1.0, 0.3);
}

TEST(MetricsFitLine, RejectsTooFewPointsOrConstantX) {
  EXPECT_THROW(fit_line({1.0}, {2.0}), std::invalid_argument);
  EXPECT_THROW(fit_line({1.0, 1.0, 1.0}, {1.0, 2.0, 3.0}), std::invalid_argument);
  EXPECT_THROW(fit_line({1.0, 2.0}, {1.0}), std::invalid_argument);
}

}  // namespace
}  // namespace hj
