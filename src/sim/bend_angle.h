// The signed bend angle of a jamming torsional spring (paper Eq. 5-11, in
// the reference form of docs/model.md) and its exact gradient.
//   e1 = x_i - x_A, e2 = x_B - x_i, t = (x_B - x_A)/|x_B - x_A|,
//   n = Eq. 3 normal at i = normalize(sigma (x_B - x_A) x (x_C2 - x_C1)),
//   phi = atan2(S, C) = atan2(e1.n, e1.t) - atan2(e2.n, e2.t),
// positive when the surface bulges outward (+n). sigma = +1 for the spring
// along x (A, B = (i, j-+1); C1, C2 = (i-+1, j)), -1 for the one along y.
// Finite and smooth through the flat state (phi = 0), unlike Eq. 7.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cmath>

namespace hj {

template <class T>
using Vec3 = Eigen::Matrix<T, 3, 1>;

// Points of one bending spring: A, i, B, C1, C2 (see above).
enum BendPoint { kBendA = 0, kBendI = 1, kBendB = 2, kBendC1 = 3, kBendC2 = 4 };

inline double bend_angle(const Eigen::Vector3d& xa, const Eigen::Vector3d& xi, const Eigen::Vector3d& xb,
                         const Eigen::Vector3d& xc1, const Eigen::Vector3d& xc2, double sigma) {
  const Eigen::Vector3d d = xb - xa;
  const Eigen::Vector3d n = (sigma * d.cross(xc2 - xc1)).normalized();
  const Eigen::Vector3d t = d.normalized();
  const Eigen::Vector3d e1 = xi - xa, e2 = xb - xi;
  const double u1 = e1.dot(t), v1 = e1.dot(n), u2 = e2.dot(t), v2 = e2.dot(n);
  return std::atan2(v1 * u2 - u1 * v2, u1 * u2 + v1 * v2);
}

// d phi / d (e1, e2, c), the three edge vectors phi depends on (d = e1 +
// e2): it is a function of 9 numbers, not of the 15 point coordinates, so
// differentiating this one (forward-mode automatic differentiation, for the
// exact Hessian) costs 9 derivative lanes rather than 15.
template <class T>
std::array<Vec3<T>, 3> bend_angle_edge_gradient(const Vec3<T>& e1, const Vec3<T>& e2, const Vec3<T>& c,
                                                double sigma) {
  using std::sqrt;
  const Vec3<T> d = e1 + e2;
  const Vec3<T> w = d.cross(c) * T(sigma);
  const T w_len = sqrt(w.squaredNorm()), d_len = sqrt(d.squaredNorm());
  const Vec3<T> n = w / w_len, t = d / d_len;
  const T u1 = e1.dot(t), v1 = e1.dot(n), u2 = e2.dot(t), v2 = e2.dot(n);
  const T r1 = u1 * u1 + v1 * v1, r2 = u2 * u2 + v2 * v2;
  // alpha_k = atan2(v_k, u_k); d alpha = (u dv - v du) / r.
  const Vec3<T> g_e1 = (n * u1 - t * v1) / r1;
  const Vec3<T> g_e2 = (n * u2 - t * v2) / r2;
  // Through t: du_k/dd = (e_k - u_k t)/|d|. Through n: dv_k/dw = g_k =
  // (e_k - v_k n)/|w|, and dw = sigma (dd x c + d x dc).
  const Vec3<T> g1 = (e1 - n * v1) / w_len, g2 = (e2 - n * v2) / w_len;
  const Vec3<T> du1_dd = (e1 - t * u1) / d_len, du2_dd = (e2 - t * u2) / d_len;
  const Vec3<T> da1_dd = (c.cross(g1) * T(sigma) * u1 - du1_dd * v1) / r1;
  const Vec3<T> da2_dd = (c.cross(g2) * T(sigma) * u2 - du2_dd * v2) / r2;
  const Vec3<T> g_d = da1_dd - da2_dd;
  const Vec3<T> g_c = (g1.cross(d) * (u1 / r1) - g2.cross(d) * (u2 / r2)) * T(sigma);
  // phi = alpha_1 - alpha_2, and d = e1 + e2 moves with both.
  return {g_e1 + g_d, g_d - g_e2, g_c};
}

// d phi / d x_p for the five points, in BendPoint order: e1 = x_i - x_A,
// e2 = x_B - x_i, c = x_C2 - x_C1.
template <class T>
std::array<Vec3<T>, 5> bend_angle_gradient(const Vec3<T>& xa, const Vec3<T>& xi, const Vec3<T>& xb,
                                           const Vec3<T>& xc1, const Vec3<T>& xc2, double sigma) {
  const auto g = bend_angle_edge_gradient<T>(xi - xa, xb - xi, xc2 - xc1, sigma);
  return {-g[0], g[0] - g[1], g[1], -g[2], g[2]};
}

}  // namespace hj
