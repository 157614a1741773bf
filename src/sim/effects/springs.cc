// Structural springs between 4-neighbours, rest length h, stiffness k, with
// a linear damper b along each spring (paper Eq. 1-2; docs/model.md).
//   F_i = k (|d| - h) d/|d| + b ((v_j - v_i) . u) u,   d = x_j - x_i.
#include <cmath>

#include "sim/effect_registry.h"
#include "sim/lattice_springs.h"

namespace hj {
namespace {

class Springs final : public Effect {
 public:
  std::string_view name() const override { return "springs"; }

  void add_forces(const ForceContext& ctx, const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& f) const override {
    const double k = ctx.params.spring_k, h = ctx.mesh.spacing();
    for_each_spring(ctx.mesh, [&](int a, int b) {
      add_tension_force(a, b, x, k * ((x.col(b) - x.col(a)).norm() - h), f);
    });
  }

  void add_stiffness(const ForceContext& ctx, const Eigen::Matrix3Xd& x, StiffnessSink& sink) const override {
    const double k = ctx.params.spring_k, h = ctx.mesh.spacing();
    // May be indefinite when a spring is compressed.
    for_each_spring(ctx.mesh, [&](int a, int b) {
      add_tension_stiffness(a, b, x, k * ((x.col(b) - x.col(a)).norm() - h), k, sink);
    });
  }

  void add_damping_forces(const ForceContext& ctx, const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& v,
                          Eigen::Matrix3Xd& f) const override {
    const double c = ctx.params.damping_b;
    if (c == 0.0) return;
    for_each_spring(ctx.mesh, [&](int a, int b) {
      const Eigen::Vector3d u = (x.col(b) - x.col(a)).normalized();
      const Eigen::Vector3d fa = c * (v.col(b) - v.col(a)).dot(u) * u;
      f.col(a) += fa;
      f.col(b) -= fa;
    });
  }

  std::optional<double> energy(const ForceContext& ctx, const Eigen::Matrix3Xd& x) const override {
    const double k = ctx.params.spring_k, h = ctx.mesh.spacing();
    double e = 0.0;
    for_each_spring(ctx.mesh, [&](int a, int b) {
      const double stretch = (x.col(b) - x.col(a)).norm() - h;
      e += 0.5 * k * stretch * stretch;
    });
    return e;
  }
};

HJ_REGISTER_EFFECT(EffectInfo{
    "springs", "structural springs between 4-neighbours with dampers along them (Eq. 1-2)", true,
    {{"spring_k", "N/m", 64.5, 1.0, 1000.0}, {"damping_b", "N s/m", 0.5, 0.0, 100.0}},
    [](const EffectParameterValues&) { return std::make_unique<Springs>(); }});

}  // namespace
}  // namespace hj
