// A follower load along the Eq. 3 normal at every inner point,
// F_p = load n_p, and its exact stiffness K = -dF/dx (not symmetric: a
// follower load has no energy). Shared by the chamber pressure and the
// effects that change the pressure a point feels.
#pragma once

#include "sim/effect.h"
#include "sim/normal.h"

namespace hj {

inline void add_normal_load(const Mesh& mesh, const Eigen::Matrix3Xd& x, double load, Eigen::Matrix3Xd& f) {
  if (load == 0.0) return;
  for_each_inner_point(mesh, [&](int p, const NormalStencil& s) { f.col(p) += load * s.normal(x); });
}

inline void add_normal_load_stiffness(const Mesh& mesh, const Eigen::Matrix3Xd& x, double load, StiffnessSink& sink) {
  if (load == 0.0) return;
  for_each_inner_point(mesh, [&](int p, const NormalStencil& s) {
    const NormalJacobian dn = s.normal_jacobian(x);
    sink.add(p, s.right, -load * dn.d_right);
    sink.add(p, s.left, load * dn.d_right);
    sink.add(p, s.up, -load * dn.d_up);
    sink.add(p, s.down, load * dn.d_up);
  });
}

}  // namespace hj
