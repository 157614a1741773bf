// Finite-difference checks shared by the effect tests: an effect's analytic
// stiffness against minus the Jacobian of its force, and its force against
// minus the gradient of its energy, over the free degrees of freedom of a
// state. Derivatives by the fourth-order central stencil
//   f'(x) = (8 (f(x+e) - f(x-e)) - (f(x+2e) - f(x-2e))) / (12 e),
// exact for polynomials up to degree 4 (e.g. a strain-stiffening spring).
#pragma once

#include <Eigen/Core>
#include <functional>
#include <random>
#include <vector>

#include "sim/effect.h"
#include "sim/stiffness_matrix.h"

namespace hj::testing_support {

// Every point not in `fixed` moved by a seeded random field of sigma (m).
inline Eigen::Matrix3Xd perturbed(const Eigen::Matrix3Xd& x, const std::vector<char>& fixed, std::mt19937& rng,
                                  double sigma = 1e-3) {
  Eigen::Matrix3Xd out = x;
  std::normal_distribution<double> move(0.0, sigma);
  for (int p = 0; p < out.cols(); ++p)
    if (!fixed[p])
      for (int c = 0; c < 3; ++c) out(c, p) += move(rng);
  return out;
}

// d value / d coordinate, `value` evaluated with `coordinate` moved by
// +-e and +-2e (and restored).
template <class Fn>
auto fourth_order_derivative(double& coordinate, double e, Fn&& value) {
  const double v = coordinate;
  coordinate = v + e;
  const auto p1 = value();
  coordinate = v - e;
  const auto m1 = value();
  coordinate = v + 2 * e;
  const auto p2 = value();
  coordinate = v - 2 * e;
  const auto m2 = value();
  coordinate = v;
  return decltype(p1)((8.0 * (p1 - m1) - (p2 - m2)) / (12.0 * e));
}

// One effect's force at x over the free DOFs of `k`.
inline Eigen::VectorXd effect_force(const Effect& effect, const ForceContext& ctx, const Eigen::Matrix3Xd& x,
                                    const StiffnessMatrix& k) {
  Eigen::Matrix3Xd f = Eigen::Matrix3Xd::Zero(3, x.cols());
  effect.add_forces(ctx, x, f);
  return k.gather(f);
}

struct DerivativeCheck {
  Eigen::MatrixXd analytic;  // K from add_stiffness, free DOFs
  Eigen::MatrixXd numeric;   // -dF/dx by central differences
  double error() const { return (analytic - numeric).norm(); }
};

// K = -dF/dx of `effect` at ctx.state.x with the points of `fixed` held.
inline DerivativeCheck check_stiffness(const Effect& effect, const ForceContext& ctx, const std::vector<char>& fixed,
                                       double eps = 1e-6) {
  const Eigen::Matrix3Xd& x0 = ctx.state.x;
  StiffnessMatrix k(ctx.mesh, fixed, [&](StiffnessSink& sink) { effect.add_stiffness(ctx, x0, sink); });
  k.set_zero();
  effect.add_stiffness(ctx, x0, k);
  DerivativeCheck out{Eigen::MatrixXd(k.matrix()), Eigen::MatrixXd(k.num_dofs(), k.num_dofs())};
  Eigen::Matrix3Xd x = x0;
  for (int d = 0; d < k.num_dofs(); ++d) {
    const int point = k.free_points()[d / 3], c = d % 3;
    out.numeric.col(d) = -fourth_order_derivative(x(c, point), eps, [&] { return effect_force(effect, ctx, x, k); });
  }
  return out;
}

struct GradientCheck {
  Eigen::VectorXd force;       // from add_forces, free DOFs
  Eigen::VectorXd minus_grad;  // -dE/dx by central differences
  double error() const { return (force - minus_grad).norm(); }
};

// Force against -grad E at ctx.state.x; the effect must have an energy.
inline GradientCheck check_energy_gradient(const Effect& effect, const ForceContext& ctx,
                                           const std::vector<char>& fixed, double eps = 1e-6) {
  StiffnessMatrix k(ctx.mesh, fixed, [](StiffnessSink&) {});
  GradientCheck out{effect_force(effect, ctx, ctx.state.x, k), Eigen::VectorXd(k.num_dofs())};
  Eigen::Matrix3Xd x = ctx.state.x;
  for (int d = 0; d < k.num_dofs(); ++d) {
    const int point = k.free_points()[d / 3], c = d % 3;
    out.minus_grad(d) = -fourth_order_derivative(x(c, point), eps, [&] { return *effect.energy(ctx, x); });
  }
  return out;
}

}  // namespace hj::testing_support
