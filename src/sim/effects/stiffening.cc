// Strain stiffening of the structural springs (a hyperelastic membrane):
//   t = k s (1 + beta (s / h)^2),  s = |d| - h,
// added to the baseline's k s as the extra tension k beta s^3 / h^2, with
// energy k beta s^4 / (4 h^2). beta = 0 is the baseline.
#include "sim/effect_registry.h"
#include "sim/lattice_springs.h"

namespace hj {
namespace {

class Stiffening final : public Effect {
 public:
  explicit Stiffening(double beta) : beta_(beta) {}
  std::string_view name() const override { return "stiffening"; }

  void add_forces(const ForceContext& ctx, const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& f) const override {
    if (beta_ == 0.0) return;
    const double c = coefficient(ctx), h = ctx.mesh.spacing();
    for_each_spring(ctx.mesh, [&](int a, int b) {
      const double s = (x.col(b) - x.col(a)).norm() - h;
      add_tension_force(a, b, x, c * s * s * s, f);
    });
  }

  void add_stiffness(const ForceContext& ctx, const Eigen::Matrix3Xd& x, StiffnessSink& sink) const override {
    if (beta_ == 0.0) return;
    const double c = coefficient(ctx), h = ctx.mesh.spacing();
    for_each_spring(ctx.mesh, [&](int a, int b) {
      const double s = (x.col(b) - x.col(a)).norm() - h;
      add_tension_stiffness(a, b, x, c * s * s * s, 3.0 * c * s * s, sink);
    });
  }

  std::optional<double> energy(const ForceContext& ctx, const Eigen::Matrix3Xd& x) const override {
    const double c = coefficient(ctx), h = ctx.mesh.spacing();
    double e = 0.0;
    for_each_spring(ctx.mesh, [&](int a, int b) {
      const double s = (x.col(b) - x.col(a)).norm() - h;
      e += 0.25 * c * s * s * s * s;
    });
    return e;
  }

  double point_stiffness_bound(const Mesh& mesh, const SurfaceParameters& params) const override {
    // Up to 50 % strain: 3 beta (s/h)^2 k per spring, 8 springs' worth.
    return 8.0 * 3.0 * beta_ * 0.25 * params.spring_k;
  }

 private:
  double coefficient(const ForceContext& ctx) const {
    const double h = ctx.mesh.spacing();
    return ctx.params.spring_k * beta_ / (h * h);
  }
  double beta_;
};

HJ_REGISTER_EFFECT(EffectInfo{"stiffening",
                              "strain stiffening of the springs: t = k s (1 + beta (s/h)^2), s = stretch",
                              false,
                              {{"beta", "1", 0.0, 0.0, 1000.0}},
                              [](const EffectParameterValues& v) { return std::make_unique<Stiffening>(v.at("beta")); }});

}  // namespace
}  // namespace hj
