// Jamming: two torsional springs at every interior point of a jammed cell,
// one along x and one along y (paper Eq. 5-9), with energy
//   E = 1/2 kappa_jam (phi - phi_eq)^2
// and forces -grad E; phi is the signed bend angle of sim/bend_angle.h and
// phi_eq the angle when the cell was jammed (perfect jam, no creep).
#include <Eigen/Core>
#include <unsupported/Eigen/AutoDiff>

#include "sim/bend_angle.h"
#include "sim/effect_registry.h"
#include "sim/jamming_springs.h"

namespace hj {
namespace {

using Deriv15 = Eigen::Matrix<double, 15, 1>;
using AD = Eigen::AutoDiffScalar<Deriv15>;

class Jamming final : public Effect {
 public:
  std::string_view name() const override { return "jamming"; }

  void add_forces(const ForceContext& ctx, const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& f) const override {
    const double kappa = ctx.params.kappa_jam;
    for_each_jammed_spring(ctx.mesh, ctx.state, [&](const BendSpring& s) {
      const Vec3<double> xa = x.col(s.p[0]), xi = x.col(s.p[1]), xb = x.col(s.p[2]), xc1 = x.col(s.p[3]),
                         xc2 = x.col(s.p[4]);
      const double torque = kappa * (bend_angle_of(x, s) - s.phi_eq);
      const auto g = bend_angle_gradient<double>(xa, xi, xb, xc1, xc2, s.sigma);
      for (int k = 0; k < 5; ++k) f.col(s.p[k]) -= torque * g[k];
    });
  }

  void add_stiffness(const ForceContext& ctx, const Eigen::Matrix3Xd& x, StiffnessSink& sink) const override {
    const double kappa = ctx.params.kappa_jam;
    for_each_jammed_spring(ctx.mesh, ctx.state, [&](const BendSpring& s) {
      std::array<Vec3<AD>, 5> xs;
      for (int k = 0; k < 5; ++k)
        for (int c = 0; c < 3; ++c) xs[k][c] = AD(x(c, s.p[k]), 15, 3 * k + c);
      const auto g = bend_angle_gradient<AD>(xs[0], xs[1], xs[2], xs[3], xs[4], s.sigma);
      const double torque = kappa * (bend_angle_of(x, s) - s.phi_eq);
      // Hess E = kappa g g^T + kappa (phi - phi_eq) Hess phi.
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
    });
  }

  std::optional<double> energy(const ForceContext& ctx, const Eigen::Matrix3Xd& x) const override {
    double e = 0.0;
    for_each_jammed_spring(ctx.mesh, ctx.state, [&](const BendSpring& s) {
      const double dphi = bend_angle_of(x, s) - s.phi_eq;
      e += 0.5 * ctx.params.kappa_jam * dphi * dphi;
    });
    return e;
  }
};

HJ_REGISTER_EFFECT(EffectInfo{"jamming", "torsional springs kappa_jam in jammed cells, signed bend angle (Eq. 5-11)",
                              true, {{"kappa_jam", "N m/rad", 4.79, 0.0, 100.0}},
                              [](const EffectParameterValues&) { return std::make_unique<Jamming>(); }});

}  // namespace
}  // namespace hj
