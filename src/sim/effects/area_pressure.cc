// Pressure on the current, stretched area instead of the constant flat
// area per point of the baseline: at an inner point with the Eq. 3 vectors
// a = x_right - x_left, b = x_up - x_down and w = a x b, the area around it
// scales as |w| / (4 h^2) (the diamond of its four neighbours), so
//   F = P A_spp w / (4 h^2)   instead of   P A_spp w / |w|.
// The effect adds weight times the difference, a follower load whose
// stiffness is exact: w is bilinear in the positions,
//   dw = -[b]x da + [a]x db.
// weight 1 is the stretched-area load, 0 the baseline; a flat rest-size
// surface feels no difference, so the levelling pressure is unchanged.
#include "sim/effect_registry.h"
#include "sim/normal_load.h"

namespace hj {
namespace {

class AreaPressure final : public Effect {
 public:
  explicit AreaPressure(double weight) : weight_(weight) {}
  std::string_view name() const override { return "area_pressure"; }

  void add_forces(const ForceContext& ctx, const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& f) const override {
    const double load = weight_ * ctx.state.pressure_pa * ctx.mesh.area_per_point();
    if (load == 0.0) return;
    const double scale = load / (4.0 * ctx.mesh.spacing() * ctx.mesh.spacing());
    for_each_inner_point(ctx.mesh, [&](int p, const NormalStencil& s) {
      const Eigen::Vector3d w = (x.col(s.right) - x.col(s.left)).cross(x.col(s.up) - x.col(s.down));
      f.col(p) += scale * w;
    });
    add_normal_load(ctx.mesh, x, -load, f);
  }

  void add_stiffness(const ForceContext& ctx, const Eigen::Matrix3Xd& x, StiffnessSink& sink) const override {
    const double load = weight_ * ctx.state.pressure_pa * ctx.mesh.area_per_point();
    if (load == 0.0) return;
    const double scale = load / (4.0 * ctx.mesh.spacing() * ctx.mesh.spacing());
    for_each_inner_point(ctx.mesh, [&](int p, const NormalStencil& s) {
      const Eigen::Vector3d a = x.col(s.right) - x.col(s.left), b = x.col(s.up) - x.col(s.down);
      // K = -dF/dx: dF/dx_right = -scale [b]x, dF/dx_up = scale [a]x.
      const Eigen::Matrix3d d_right = -scale * cross_matrix(b), d_up = scale * cross_matrix(a);
      sink.add(p, s.right, -d_right);
      sink.add(p, s.left, d_right);
      sink.add(p, s.up, -d_up);
      sink.add(p, s.down, d_up);
    });
    add_normal_load_stiffness(ctx.mesh, x, -load, sink);
  }

 private:
  double weight_;
};

HJ_REGISTER_EFFECT(EffectInfo{"area_pressure",
                              "pressure on the current stretched area (weight 1) instead of the flat one (weight 0)",
                              false,
                              {{"weight", "1", 1.0, 0.0, 1.0}},
                              [](const EffectParameterValues& v) { return std::make_unique<AreaPressure>(v.at("weight")); }});

}  // namespace
}  // namespace hj
