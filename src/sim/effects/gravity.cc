// Gravity: each point carries m = M / N (fixed points included) and feels
// m g along -z (docs/model.md).
#include "sim/effect_registry.h"

namespace hj {
namespace {

class Gravity final : public Effect {
 public:
  std::string_view name() const override { return "gravity"; }

  void add_forces(const ForceContext& ctx, const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& f) const override {
    f.row(2).array() -= ctx.params.point_mass(ctx.mesh) * ctx.params.gravity;
  }

  void add_stiffness(const ForceContext&, const Eigen::Matrix3Xd&, StiffnessSink&) const override {}

  std::optional<double> energy(const ForceContext& ctx, const Eigen::Matrix3Xd& x) const override {
    return ctx.params.point_mass(ctx.mesh) * ctx.params.gravity * x.row(2).sum();
  }
};

HJ_REGISTER_EFFECT(EffectInfo{"gravity", "weight m g of each point, m = M / N", true,
                              {{"mass_kg", "kg", 0.55, 0.01, 100.0}},
                              [](const EffectParameterValues&) { return std::make_unique<Gravity>(); }});

}  // namespace
}  // namespace hj
