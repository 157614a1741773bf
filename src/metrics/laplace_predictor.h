// The Laplace predictor of Stanley & Okamura 2015, section 5.4 (Eq. 14,
// Table 2): how well a goal can be rendered, guessed from the goal alone by
// the mean of its inverted Laplacian-filtered image, and the line fit to it.
#pragma once

#include <vector>

#include <Eigen/Core>

namespace hj {

// MATLAB fspecial('laplacian', alpha_l):
//   4 / (alpha_l + 1) * [ alpha_l/4      (1-alpha_l)/4  alpha_l/4
//                         (1-alpha_l)/4  -1             (1-alpha_l)/4
//                         alpha_l/4      (1-alpha_l)/4  alpha_l/4     ].
// Its entries sum to zero. Eq. 14 uses alpha_l = 1/3.
// @throws std::invalid_argument when alpha_l is outside [0, 1].
Eigen::Matrix3d laplacian_kernel(double alpha_l);

// Our reading of "the mean of the inverted filtered image", in [0, 1]:
//  1. normalise the goal to [0, 1] by its min and max over finite pixels,
//     then set non-finite pixels to 0 (the lowest level);
//  2. filter with laplacian_kernel(alpha_l), zero padding outside the image
//     (cv::filter2D, BORDER_CONSTANT 0);
//  3. take |response|, clamp it to [0, 1], invert it (1 - x);
//  4. return the mean over all pixels.
// Smooth goals score near 1, busy ones (a checkerboard) near 0. A flat goal,
// at any height, normalises to all 0, so it has no response even at the
// padded border and gives exactly 1. A non-flat goal above its minimum at
// the border does see an edge there: a border pixel (not a corner) at 1
// whose neighbours are at 1 responds 1 for any alpha_l, so it counts 0.
// @throws std::invalid_argument when goal is empty, has no finite pixel, or
// alpha_l is outside [0, 1].
double laplace_mean(const Eigen::MatrixXd& goal, double alpha_l = 1.0 / 3.0);

struct LinearFit {
  double slope = 0.0;
  double intercept = 0.0;
  double r2 = 0.0;  // 1 - SS_res / SS_tot; 1 when y is constant (the line fits exactly)
  int n = 0;
};

// Least-squares line y = slope x + intercept, as Table 2 fits correlation
// against laplace_mean.
// @throws std::invalid_argument when x and y differ in length, hold fewer than
// 2 points or a non-finite value, or x does not vary.
LinearFit fit_line(const std::vector<double>& x, const std::vector<double>& y);

}  // namespace hj
