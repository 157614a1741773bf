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

// sink += the spring's 5 x 5 blocks of K = -dF/dx. phi depends on the
// points only through three edge vectors q = (e1, e2, c), q = P x, so
// Hess_x phi = P^T Hess_q phi P: the Hessian is differentiated in those 9
// variables and spread over the points by P's +-1 blocks.
inline void add_bend_spring_stiffness(const Eigen::Matrix3Xd& x, const BendSpring& s, double kappa,
                                      StiffnessSink& sink) {
  using AD = Eigen::AutoDiffScalar<Eigen::Matrix<double, 9, 1>>;
  // The points each edge runs from (tail) and to (head): e1 = x_i - x_A,
  // e2 = x_B - x_i, c = x_C2 - x_C1.
  constexpr int kTail[3] = {kBendA, kBendI, kBendC1}, kHead[3] = {kBendI, kBendB, kBendC2};
  std::array<Vec3<AD>, 3> q;
  for (int e = 0; e < 3; ++e)
    for (int c = 0; c < 3; ++c) q[e][c] = AD(x(c, s.p[kHead[e]]) - x(c, s.p[kTail[e]]), 9, 3 * e + c);
  const auto g = bend_angle_edge_gradient<AD>(q[0], q[1], q[2], s.sigma);
  const double torque = kappa * (bend_angle_of(x, s) - s.phi_eq);
  Eigen::Matrix<double, 15, 1> grad = Eigen::Matrix<double, 15, 1>::Zero();
  Eigen::Matrix<double, 9, 9> hess_q;
  for (int e = 0; e < 3; ++e)
    for (int c = 0; c < 3; ++c) {
      grad(3 * kHead[e] + c) += g[e][c].value();
      grad(3 * kTail[e] + c) -= g[e][c].value();
      hess_q.row(3 * e + c) = g[e][c].derivatives().transpose();
    }
  Eigen::Matrix<double, 15, 15> stiff = kappa * grad * grad.transpose();
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) {
      const Eigen::Matrix3d h = torque * hess_q.block<3, 3>(3 * a, 3 * b);
      stiff.block<3, 3>(3 * kHead[a], 3 * kHead[b]) += h;
      stiff.block<3, 3>(3 * kHead[a], 3 * kTail[b]) -= h;
      stiff.block<3, 3>(3 * kTail[a], 3 * kHead[b]) -= h;
      stiff.block<3, 3>(3 * kTail[a], 3 * kTail[b]) += h;
    }
  for (int r = 0; r < 5; ++r)
    for (int c = 0; c < 5; ++c) sink.add(s.p[r], s.p[c], stiff.block<3, 3>(3 * r, 3 * c));
}

}  // namespace hj
