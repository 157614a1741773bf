// The Laplace predictor of Stanley & Okamura 2015, section 5.4 (Eq. 14):
// fspecial-style kernel, mean of the inverted filtered goal, Table 2's line fit.
#include "metrics/laplace_predictor.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include <opencv2/core/eigen.hpp>
#include <opencv2/imgproc.hpp>

namespace hj {

Eigen::Matrix3d laplacian_kernel(double alpha_l) {
  if (!(alpha_l >= 0.0 && alpha_l <= 1.0))
    throw std::invalid_argument("alpha_l (the Laplacian's diagonal weight, dimensionless) must be in [0, 1], got " +
                                std::to_string(alpha_l));
  const double corner = alpha_l / 4.0;
  const double side = (1.0 - alpha_l) / 4.0;
  Eigen::Matrix3d k;
  k << corner, side, corner,  //
      side, -1.0, side,       //
      corner, side, corner;
  return 4.0 / (alpha_l + 1.0) * k;
}

double laplace_mean(const Eigen::MatrixXd& goal, double alpha_l) {
  const Eigen::Matrix3d kernel = laplacian_kernel(alpha_l);
  if (goal.size() == 0) throw std::invalid_argument("laplace_mean: the goal image is empty");

  // Range over the finite pixels.
  double lo = std::numeric_limits<double>::infinity();
  double hi = -lo;
  for (Eigen::Index k = 0; k < goal.size(); ++k)
    if (std::isfinite(goal(k))) {
      lo = std::min(lo, goal(k));
      hi = std::max(hi, goal(k));
    }
  if (!(lo <= hi)) throw std::invalid_argument("laplace_mean: the goal image has no finite pixel");

  // Normalised goal, (rows x cols) in [0, 1]; non-finite and flat pixels are 0.
  Eigen::MatrixXd normalised = Eigen::MatrixXd::Zero(goal.rows(), goal.cols());
  if (hi > lo)
    for (Eigen::Index k = 0; k < goal.size(); ++k)
      if (std::isfinite(goal(k))) normalised(k) = (goal(k) - lo) / (hi - lo);

  // Laplacian response with zero padding.
  cv::Mat src, response, cv_kernel;
  cv::eigen2cv(normalised, src);
  cv::eigen2cv(kernel, cv_kernel);
  cv::filter2D(src, response, CV_64F, cv_kernel, cv::Point(-1, -1), 0.0, cv::BORDER_CONSTANT);

  // Inverted, clamped magnitude, averaged.
  cv::Mat magnitude = cv::min(cv::abs(response), 1.0);
  return 1.0 - cv::mean(magnitude)[0];
}

LinearFit fit_line(const std::vector<double>& x, const std::vector<double>& y) {
  if (x.size() != y.size())
    throw std::invalid_argument("fit_line: x has " + std::to_string(x.size()) + " values but y has " +
                                std::to_string(y.size()));
  if (x.size() < 2)
    throw std::invalid_argument("fit_line: a line needs at least 2 points, got " + std::to_string(x.size()));
  for (std::size_t i = 0; i < x.size(); ++i)
    if (!std::isfinite(x[i]) || !std::isfinite(y[i]))
      throw std::invalid_argument("fit_line: point " + std::to_string(i) + " is not finite");
  const auto [x_min, x_max] = std::minmax_element(x.begin(), x.end());
  if (*x_min == *x_max) throw std::invalid_argument("fit_line: every x is the same, so the slope is undefined");

  const double n = static_cast<double>(x.size());
  double mx = 0.0, my = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    mx += x[i];
    my += y[i];
  }
  mx /= n;
  my /= n;

  // Centred sums of squares and products.
  double sxx = 0.0, sxy = 0.0, syy = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    sxx += (x[i] - mx) * (x[i] - mx);
    sxy += (x[i] - mx) * (y[i] - my);
    syy += (y[i] - my) * (y[i] - my);
  }

  LinearFit fit;
  fit.n = static_cast<int>(x.size());
  fit.slope = sxy / sxx;
  fit.intercept = my - fit.slope * mx;
  double ss_res = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    const double e = y[i] - (fit.slope * x[i] + fit.intercept);
    ss_res += e * e;
  }
  const auto [y_min, y_max] = std::minmax_element(y.begin(), y.end());
  fit.r2 = *y_min == *y_max ? 1.0 : std::clamp(1.0 - ss_res / syy, 0.0, 1.0);
  return fit;
}

}  // namespace hj
