// Jamming: two torsional springs at every interior point of a jammed cell,
// one along x and one along y (paper Eq. 5-9), with energy
//   E = 1/2 kappa_jam (phi - phi_eq)^2
// and forces -grad E; phi is the signed bend angle of sim/bend_angle.h and
// phi_eq the angle when the cell was jammed (perfect jam, no creep).
#include "sim/bend_spring_terms.h"
#include "sim/effect_registry.h"
#include "sim/jamming_springs.h"

namespace hj {
namespace {

class Jamming final : public Effect {
 public:
  std::string_view name() const override { return "jamming"; }

  void add_forces(const ForceContext& ctx, const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& f) const override {
    for_each_jammed_spring(ctx.mesh, ctx.state,
                           [&](const BendSpring& s) { add_bend_spring_force(x, s, ctx.params.kappa_jam, f); });
  }

  void add_stiffness(const ForceContext& ctx, const Eigen::Matrix3Xd& x, StiffnessSink& sink) const override {
    for_each_jammed_spring(ctx.mesh, ctx.state,
                           [&](const BendSpring& s) { add_bend_spring_stiffness(x, s, ctx.params.kappa_jam, sink); });
  }

  std::optional<double> energy(const ForceContext& ctx, const Eigen::Matrix3Xd& x) const override {
    double e = 0.0;
    for_each_jammed_spring(ctx.mesh, ctx.state,
                           [&](const BendSpring& s) { e += bend_spring_energy(x, s, ctx.params.kappa_jam); });
    return e;
  }
};

HJ_REGISTER_EFFECT(EffectInfo{"jamming", "torsional springs kappa_jam in jammed cells, signed bend angle (Eq. 5-11)",
                              true, {{"kappa_jam", "N m/rad", 4.79, 0.0, 100.0}},
                              [](const EffectParameterValues&) { return std::make_unique<Jamming>(); }});

}  // namespace
}  // namespace hj
