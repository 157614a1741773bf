// The structural springs of the mesh (docs/model.md, "Forces") and the
// derivatives of a central force along one of them, shared by the baseline
// springs and the effects that change them (stiffening, jam contraction,
// per-cell stiffness, a compliant edge).
#pragma once

#include <Eigen/Core>

#include "model/mesh.h"
#include "sim/effect.h"

namespace hj {

// Calls fn(a, b) for every spring between 4-neighbours a < b with at least
// one end off the clamped edge.
template <class Fn>
void for_each_spring(const Mesh& mesh, Fn&& fn) {
  const int nr = mesh.point_rows(), nc = mesh.point_cols();
  for (int i = 0; i < nr; ++i) {
    for (int j = 0; j < nc; ++j) {
      const int a = mesh.index(i, j);
      if (j + 1 < nc && !(mesh.is_boundary(a) && mesh.is_boundary(a + 1))) fn(a, a + 1);
      if (i + 1 < nr && !(mesh.is_boundary(a) && mesh.is_boundary(a + nc))) fn(a, a + nc);
    }
  }
}

// A tension t (N, > 0 pulls the ends together) along the spring a-b:
// F_a = t u, F_b = -t u, u = (x_b - x_a) / |x_b - x_a|.
inline void add_tension_force(int a, int b, const Eigen::Matrix3Xd& x, double tension, Eigen::Matrix3Xd& f) {
  const Eigen::Vector3d d = x.col(b) - x.col(a);
  const Eigen::Vector3d fa = (tension / d.norm()) * d;
  f.col(a) += fa;
  f.col(b) -= fa;
}

// sink += K = -dF/dx of a tension t(len) with dt/dlen = t_prime:
// dF_a/dx_b = t' uu^T + (t / len)(I - uu^T), and the three other blocks by symmetry.
inline void add_tension_stiffness(int a, int b, const Eigen::Matrix3Xd& x, double tension, double tension_prime,
                                  StiffnessSink& sink) {
  const Eigen::Vector3d d = x.col(b) - x.col(a);
  const double len = d.norm();
  const Eigen::Vector3d u = d / len;
  const Eigen::Matrix3d uu = u * u.transpose();
  const Eigen::Matrix3d ks = tension_prime * uu + (tension / len) * (Eigen::Matrix3d::Identity() - uu);
  sink.add(a, a, ks);
  sink.add(b, b, ks);
  sink.add(a, b, -ks);
  sink.add(b, a, -ks);
}

}  // namespace hj
