// How well a predicted surface matches a goal image: the 2-D correlation
// coefficient of Stanley & Okamura 2015, Eq. 12 (MATLAB corr2), after the
// predicted mesh heights are scaled up to the goal's size by bicubic interpolation.
#pragma once

#include <optional>
#include <string>

#include <Eigen/Core>

namespace hj {

struct Correlation {
  std::optional<double> value;   // r in [-1, 1]; empty when undefined
  std::string undefined_reason;  // set when value is empty, readable by a user
  int samples = 0;               // entries finite in both inputs
};

// Eq. 12, r = sum((A - mA)(B - mB)) / sqrt(sum((A - mA)^2) sum((B - mB)^2)),
// over the entries finite in both a and b (the means too). Undefined when
// fewer than 2 such entries remain or either input does not vary over them.
// @throws std::invalid_argument when the shapes differ (the message names both).
Correlation correlate(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b);

// m scaled to (rows x cols) by cv::resize with INTER_CUBIC. Alignment is by
// pixel centres, as in MATLAB imresize: output (i, j) samples m at
//   ((i + 0.5) m.rows() / rows - 0.5, (j + 0.5) m.cols() / cols - 0.5),
// so corners are not mapped onto corners, and taps past the border repeat
// the edge entry. The kernel is Keys' cubic with a = -0.75 (MATLAB uses
// -0.5): it passes through the samples and keeps constants, but bends a
// linear ramp between samples, by 0.5 t (1 - t)(1 - 2 t) of a sample step
// at fraction t, at most sqrt(3)/36 ~ 0.048. OpenCV computes the weights in
// float, so outputs are good to ~1e-7 relative even for doubles; a constant
// m is returned as exactly that constant, since that rounding noise would
// otherwise turn a flat prediction into a meaningless r instead of an
// undefined one. A NaN in m makes every output within two source steps NaN.
// @throws std::invalid_argument when m is empty or rows, cols < 1.
Eigen::MatrixXd upscale_bicubic(const Eigen::MatrixXd& m, int rows, int cols);

// The paper's score: predicted_points (mesh point heights, any small grid)
// scaled up to goal_image's size, then correlated with it. NaN goal pixels
// (outside the shape) do not count. Reasons name "the goal" / "the prediction".
// @throws std::invalid_argument when either is empty or a predicted height
// is not finite.
Correlation correlate_with_goal(const Eigen::MatrixXd& goal_image, const Eigen::MatrixXd& predicted_points);

}  // namespace hj
