// Energy, force and exact stiffness of one torsional (bending) spring
//   E = 1/2 kappa (phi - phi_eq)^2,  F = -kappa (phi - phi_eq) grad phi,
//   K = Hess E = kappa grad phi grad phi^T + kappa (phi - phi_eq) Hess phi,
// with phi the signed bend angle of sim/bend_angle.h; Hess phi by forward
// automatic differentiation of its exact gradient. Shared by the jamming
// springs and the bare-membrane bending effect.
#pragma once

#include <Eigen/Core>
#include <unsupported/Eigen/AutoDiff>

#include "sim/effect.h"
#include "sim/jamming_springs.h"

namespace hj {

inline double bend_spring_energy(const Eigen::Matrix3Xd& x, const BendSpring& s, double kappa) {
  const double dphi = bend_angle_of(x, s) - s.phi_eq;
  return 0.5 * kappa * dphi * dphi;
}

// f (3 x N) += the spring's force on its five points.
inline void add_bend_spring_force(const Eigen::Matrix3Xd& x, const BendSpring& s, double kappa, Eigen::Matrix3Xd& f) {
  const Vec3<double> xa = x.col(s.p[0]), xi = x.col(s.p[1]), xb = x.col(s.p[2]), xc1 = x.col(s.p[3]),
                     xc2 = x.col(s.p[4]);
  const double torque = kappa * (bend_angle_of(x, s) - s.phi_eq);
  const auto g = bend_angle_gradient<double>(xa, xi, xb, xc1, xc2, s.sigma);
  for (int k = 0; k < 5; ++k) f.col(s.p[k]) -= torque * g[k];
}

// sink += the spring's 5 x 5 blocks of K = -dF/dx.
inline void add_bend_spring_stiffness(const Eigen::Matrix3Xd& x, const BendSpring& s, double kappa,
                                      StiffnessSink& sink) {
  using AD = Eigen::AutoDiffScalar<Eigen::Matrix<double, 15, 1>>;
  std::array<Vec3<AD>, 5> xs;
  for (int k = 0; k < 5; ++k)
    for (int c = 0; c < 3; ++c) xs[k][c] = AD(x(c, s.p[k]), 15, 3 * k + c);
  const auto g = bend_angle_gradient<AD>(xs[0], xs[1], xs[2], xs[3], xs[4], s.sigma);
  const double torque = kappa * (bend_angle_of(x, s) - s.phi_eq);
  Eigen::Matrix<double, 15, 1> grad;
  Eigen::Matrix<double, 15, 15> hess;
  for (int k = 0; k < 5; ++k)
    for (int c = 0; c < 3; ++c) {
      grad(3 * k + c) = g[k][c].value();
      hess.row(3 * k + c) = g[k][c].derivatives().transpose();
    }
  const Eigen::Matrix<double, 15, 15> stiff = kappa * grad * grad.transpose() + torque * hess;
  for (int r = 0; r < 5; ++r)
    for (int c = 0; c < 5; ++c) sink.add(s.p[r], s.p[c], stiff.block<3, 3>(3 * r, 3 * c));
}

}  // namespace hj
