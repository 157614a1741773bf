// Bending stiffness of the bare membrane: two torsional springs toward flat
// at every interior and border point (not at the nodes, nor on the clamped
// edge), one along x and one along y, in every cell, jammed or not:
//   E = 1/2 kappa_bend phi^2   (phi_eq = 0),
// with phi the signed bend angle of the jamming springs (sim/bend_angle.h).
// A jammed cell has both its jam springs and these. This is how the shared
// dataset demo-bending was made (its README, "Effects").
#include "sim/bend_spring_terms.h"
#include "sim/effect_registry.h"

namespace hj {
namespace {

// Calls fn(spring) for both springs (phi_eq = 0) of every interior and border point.
template <class Fn>
void for_each_membrane_spring(const Mesh& mesh, Fn&& fn) {
  for (int p = 0; p < mesh.num_points(); ++p) {
    const PointKind kind = mesh.kind(p);
    if (kind != PointKind::kInterior && kind != PointKind::kBorder) continue;
    for (const BendSpring& s : bend_springs_at(mesh, p)) fn(s);
  }
}

class Bending final : public Effect {
 public:
  explicit Bending(double kappa) : kappa_(kappa) {}
  std::string_view name() const override { return "bending"; }

  void add_forces(const ForceContext& ctx, const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& f) const override {
    if (kappa_ == 0.0) return;
    for_each_membrane_spring(ctx.mesh, [&](const BendSpring& s) { add_bend_spring_force(x, s, kappa_, f); });
  }

  void add_stiffness(const ForceContext& ctx, const Eigen::Matrix3Xd& x, StiffnessSink& sink) const override {
    if (kappa_ == 0.0) return;
    for_each_membrane_spring(ctx.mesh, [&](const BendSpring& s) { add_bend_spring_stiffness(x, s, kappa_, sink); });
  }

  std::optional<double> energy(const ForceContext& ctx, const Eigen::Matrix3Xd& x) const override {
    double e = 0.0;
    for_each_membrane_spring(ctx.mesh, [&](const BendSpring& s) { e += bend_spring_energy(x, s, kappa_); });
    return e;
  }

  double point_stiffness_bound(const Mesh& mesh, const SurfaceParameters&) const override {
    const double h = mesh.spacing();
    return 32.0 * kappa_ / (h * h);  // as a jammed spring (explicit_euler.cc)
  }

 private:
  double kappa_;
};

HJ_REGISTER_EFFECT(EffectInfo{"bending",
                              "bare-membrane bending: torsional springs kappa_bend toward flat at every interior "
                              "and border point, in every cell",
                              false,
                              {{"kappa_bend", "N m/rad", 0.0, 0.0, 1.0}},
                              [](const EffectParameterValues& v) { return std::make_unique<Bending>(v.at("kappa_bend")); }});

}  // namespace
}  // namespace hj
