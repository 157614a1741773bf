// Structural springs between 4-neighbours, rest length h, stiffness k, with
// a linear damper b along each spring (paper Eq. 1-2; docs/model.md).
//   F_i = k (|d| - h) d/|d| + b ((v_j - v_i) . u) u,   d = x_j - x_i.
#include <cmath>

#include "sim/effect_registry.h"

namespace hj {
namespace {

// Calls fn(i_point, j_point) for every spring with at least one free end.
template <class Fn>
void for_each_spring(const Mesh& mesh, Fn&& fn) {
  const int nr = mesh.point_rows(), nc = mesh.point_cols();
  for (int i = 0; i < nr; ++i) {
    for (int j = 0; j < nc; ++j) {
      const int a = mesh.index(i, j);
      if (j + 1 < nc && !(mesh.is_boundary(a) && mesh.is_boundary(a + 1))) fn(a, a + 1);
      if (i + 1 < nr && !(mesh.is_boundary(a) && mesh.is_boundary(a + nc))) fn(a, a + nc);
    }
  }
}

class Springs final : public Effect {
 public:
  std::string_view name() const override { return "springs"; }

  void add_forces(const ForceContext& ctx, const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& f) const override {
    const double k = ctx.params.spring_k, h = ctx.mesh.spacing();
    for_each_spring(ctx.mesh, [&](int a, int b) {
      const Eigen::Vector3d d = x.col(b) - x.col(a);
      const double len = d.norm();
      const Eigen::Vector3d fa = (k * (len - h) / len) * d;
      f.col(a) += fa;
      f.col(b) -= fa;
    });
  }

  void add_stiffness(const ForceContext& ctx, const Eigen::Matrix3Xd& x, StiffnessSink& sink) const override {
    const double k = ctx.params.spring_k, h = ctx.mesh.spacing();
    for_each_spring(ctx.mesh, [&](int a, int b) {
      const Eigen::Vector3d d = x.col(b) - x.col(a);
      const double len = d.norm();
      const Eigen::Vector3d u = d / len;
      const Eigen::Matrix3d uu = u * u.transpose();
      // dF_a/dx_b; may be indefinite when the spring is compressed.
      const Eigen::Matrix3d ks = k * (uu + (1.0 - h / len) * (Eigen::Matrix3d::Identity() - uu));
      sink.add(a, a, ks);
      sink.add(b, b, ks);
      sink.add(a, b, -ks);
      sink.add(b, a, -ks);
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
