#include "calib/bounded_step.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace hj {

namespace {

// min |r + J d|^2 with the components in `fixed` (finite) held there.
Eigen::VectorXd step_with_fixed(const Eigen::MatrixXd& j, const Eigen::VectorXd& r, const Eigen::VectorXd& fixed) {
  const int p = static_cast<int>(j.cols());
  Eigen::VectorXd step = Eigen::VectorXd::Zero(p);
  std::vector<int> free;
  Eigen::VectorXd rest = r;
  for (int k = 0; k < p; ++k) {
    if (std::isfinite(fixed[k])) {
      step[k] = fixed[k];
      rest += j.col(k) * fixed[k];
    } else {
      free.push_back(k);
    }
  }
  if (free.empty()) return step;
  Eigen::MatrixXd jf(j.rows(), free.size());
  for (size_t k = 0; k < free.size(); ++k) jf.col(k) = j.col(free[k]);
  Eigen::MatrixXd jtj = jf.transpose() * jf;
  jtj.diagonal() *= 1.0 + 1e-6;
  const Eigen::VectorXd d = -jtj.ldlt().solve(jf.transpose() * rest);
  for (size_t k = 0; k < free.size(); ++k) step[free[k]] = std::isfinite(d[k]) ? d[k] : 0.0;
  return step;
}

}  // namespace

Eigen::VectorXd bounded_gauss_newton_step(const Eigen::MatrixXd& j, const Eigen::VectorXd& r,
                                          const Eigen::VectorXd& lo, const Eigen::VectorXd& hi) {
  const int p = static_cast<int>(j.cols());
  Eigen::VectorXd fixed = Eigen::VectorXd::Constant(p, std::numeric_limits<double>::quiet_NaN());
  Eigen::VectorXd d;
  for (int pass = 0; pass <= p; ++pass) {
    d = step_with_fixed(j, r, fixed);
    bool clamped = false;
    for (int k = 0; k < p; ++k) {
      if (std::isfinite(fixed[k]) || (d[k] >= lo[k] && d[k] <= hi[k])) continue;
      fixed[k] = std::clamp(d[k], lo[k], hi[k]);
      clamped = true;
    }
    if (!clamped) break;
  }
  return d;
}

}  // namespace hj
