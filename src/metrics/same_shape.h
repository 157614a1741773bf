// One shape check for the metrics that compare height fields point by point.
#pragma once

#include <Eigen/Core>
#include <stdexcept>
#include <string>

namespace hj {

// "R x C".
inline std::string shape_text(const Eigen::MatrixXd& m) {
  return std::to_string(m.rows()) + " x " + std::to_string(m.cols());
}

// @throws std::invalid_argument "WHAT: shapes differ, R x C and R' x C'".
inline void check_same_shape(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b, const char* what) {
  if (a.rows() != b.rows() || a.cols() != b.cols())
    throw std::invalid_argument(std::string(what) + ": shapes differ, " + shape_text(a) + " and " + shape_text(b));
}

}  // namespace hj
