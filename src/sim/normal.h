// The Eq. 3 normal at an inner mesh point and its derivatives:
//   w = (x_right - x_left) x (x_up - x_down),  n = w / |w|,
// where right/left are (i, j+-1) and up/down are (i+-1, j).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "model/mesh.h"

namespace hj {

// dn/dx_right = d_right (= -dn/dx_left), dn/dx_up = d_up (= -dn/dx_down).
struct NormalJacobian {
  Eigen::Matrix3d d_right;
  Eigen::Matrix3d d_up;
};

inline Eigen::Matrix3d cross_matrix(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return m;
}

struct NormalStencil {
  int left, right, down, up;

  Eigen::Vector3d normal(const Eigen::Matrix3Xd& x) const {
    return (x.col(right) - x.col(left)).cross(x.col(up) - x.col(down)).normalized();
  }

  NormalJacobian normal_jacobian(const Eigen::Matrix3Xd& x) const {
    const Eigen::Vector3d a = x.col(right) - x.col(left), b = x.col(up) - x.col(down);
    const Eigen::Vector3d w = a.cross(b);
    const double len = w.norm();
    const Eigen::Vector3d n = w / len;
    const Eigen::Matrix3d proj = (Eigen::Matrix3d::Identity() - n * n.transpose()) / len;
    // dw = da x b + a x db = -[b]x da + [a]x db.
    return {-proj * cross_matrix(b), proj * cross_matrix(a)};
  }
};

// Calls fn(point, stencil) for every point off the clamped edge.
template <class Fn>
void for_each_inner_point(const Mesh& mesh, Fn&& fn) {
  const int nc = mesh.point_cols();
  for (int i = 1; i + 1 < mesh.point_rows(); ++i)
    for (int j = 1; j + 1 < nc; ++j) {
      const int p = mesh.index(i, j);
      fn(p, NormalStencil{p - 1, p + 1, p - nc, p + nc});
    }
}

}  // namespace hj
