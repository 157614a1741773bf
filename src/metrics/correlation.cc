// The correlation score of Stanley & Okamura 2015, Eq. 12 (MATLAB corr2),
// and the bicubic upscaling of predicted heights to the goal image it needs.
#include "metrics/correlation.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>

#include <opencv2/core/eigen.hpp>
#include <opencv2/imgproc.hpp>

namespace hj {
namespace {

std::string shape_of(const Eigen::MatrixXd& m) {
  return "(" + std::to_string(m.rows()) + " x " + std::to_string(m.cols()) + ")";
}

Correlation undefined(std::string reason, int samples) {
  Correlation c;
  c.undefined_reason = std::move(reason);
  c.samples = samples;
  return c;
}

std::string flat_reason(const std::string& name, const std::string& quantity, int samples) {
  return name + " is flat: its " + quantity + " do not vary over the " + std::to_string(samples) +
         " samples that count, so correlation is undefined";
}

// Eq. 12 with the inputs named in the reasons, e.g. ("the goal", "heights").
Correlation correlate_named(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b, const std::string& name_a,
                            const std::string& name_b, const std::string& quantity) {
  if (a.rows() != b.rows() || a.cols() != b.cols())
    throw std::invalid_argument("correlation needs inputs of one shape, got " + name_a + " " + shape_of(a) +
                                " and " + name_b + " " + shape_of(b));

  // Pass 1 over the samples finite in both: their count, sums and ranges.
  const auto both_finite = [&](Eigen::Index k) { return std::isfinite(a(k)) && std::isfinite(b(k)); };
  int n = 0;
  double sum_a = 0.0, sum_b = 0.0;
  double a_min = INFINITY, a_max = -INFINITY, b_min = INFINITY, b_max = -INFINITY;
  for (Eigen::Index k = 0; k < a.size(); ++k) {
    if (!both_finite(k)) continue;
    ++n;
    sum_a += a(k), sum_b += b(k);
    a_min = std::min(a_min, a(k)), a_max = std::max(a_max, a(k));
    b_min = std::min(b_min, b(k)), b_max = std::max(b_max, b(k));
  }
  if (n < 2)
    return undefined("only " + std::to_string(n) + " sample(s) are valid (finite) in both " + name_a + " and " +
                         name_b + ", and correlation needs at least 2",
                     n);

  // Flatness is tested exactly (min == max): a computed variance of a
  // constant can come out as rounding noise instead of zero.
  if (a_min == a_max) return undefined(flat_reason(name_a, quantity, n), n);
  if (b_min == b_max) return undefined(flat_reason(name_b, quantity, n), n);

  // Pass 2: deviations from the means, scaled by their ranges so the sums
  // of squares cannot overflow or underflow (r does not change).
  const double mean_a = sum_a / double(n), mean_b = sum_b / double(n);
  const double range_a = a_max - a_min, range_b = b_max - b_min;
  double sab = 0.0, saa = 0.0, sbb = 0.0;
  for (Eigen::Index k = 0; k < a.size(); ++k) {
    if (!both_finite(k)) continue;
    const double da = (a(k) - mean_a) / range_a, db = (b(k) - mean_b) / range_b;
    sab += da * db;
    saa += da * da;
    sbb += db * db;
  }
  Correlation c;
  c.value = std::clamp(sab / std::sqrt(saa * sbb), -1.0, 1.0);
  c.samples = n;
  return c;
}

}  // namespace

Correlation correlate(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return correlate_named(a, b, "the first input", "the second input", "values");
}

Eigen::MatrixXd upscale_bicubic(const Eigen::MatrixXd& m, int rows, int cols) {
  if (m.size() == 0) throw std::invalid_argument("upscale_bicubic: the input is empty " + shape_of(m));
  if (rows < 1 || cols < 1)
    throw std::invalid_argument("upscale_bicubic: the output size must be at least 1 x 1, got (" +
                                std::to_string(rows) + " x " + std::to_string(cols) + ")");
  if (m.minCoeff() == m.maxCoeff()) return Eigen::MatrixXd::Constant(rows, cols, m(0, 0));
  cv::Mat src, dst;
  cv::eigen2cv(m, src);
  cv::resize(src, dst, cv::Size(cols, rows), 0.0, 0.0, cv::INTER_CUBIC);
  Eigen::MatrixXd out;
  cv::cv2eigen(dst, out);
  return out;
}

Correlation correlate_with_goal(const Eigen::MatrixXd& goal_image, const Eigen::MatrixXd& predicted_points) {
  if (goal_image.size() == 0) throw std::invalid_argument("the goal image is empty " + shape_of(goal_image));
  if (predicted_points.size() == 0)
    throw std::invalid_argument("the predicted heights are empty " + shape_of(predicted_points));
  if (!predicted_points.allFinite())
    throw std::invalid_argument("the predicted heights " + shape_of(predicted_points) +
                                " contain a NaN or infinite value");
  const Eigen::MatrixXd predicted_image =
      upscale_bicubic(predicted_points, static_cast<int>(goal_image.rows()), static_cast<int>(goal_image.cols()));
  return correlate_named(goal_image, predicted_image, "the goal", "the prediction", "heights");
}

}  // namespace hj
