// The pressure regulator's gain and offset: the chamber holds
//   P_eff = gain P + offset
// for a commanded P (the offset acts at P = 0 too). Added to the baseline's
// P A_spp n as the follower load ((gain - 1) P + offset) A_spp n on every
// inner point, with its exact (non-symmetric) stiffness. gain 1, offset 0
// is the baseline.
#include "sim/effect_registry.h"
#include "sim/normal_load.h"

namespace hj {
namespace {

class PressureOffset final : public Effect {
 public:
  PressureOffset(double gain, double offset_pa) : gain_(gain), offset_pa_(offset_pa) {}
  std::string_view name() const override { return "pressure_offset"; }

  void add_forces(const ForceContext& ctx, const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& f) const override {
    add_normal_load(ctx.mesh, x, extra_load(ctx), f);
  }

  void add_stiffness(const ForceContext& ctx, const Eigen::Matrix3Xd& x, StiffnessSink& sink) const override {
    add_normal_load_stiffness(ctx.mesh, x, extra_load(ctx), sink);
  }

 private:
  double extra_load(const ForceContext& ctx) const {
    return ((gain_ - 1.0) * ctx.state.pressure_pa + offset_pa_) * ctx.mesh.area_per_point();
  }
  double gain_, offset_pa_;
};

HJ_REGISTER_EFFECT(EffectInfo{"pressure_offset",
                              "pressure regulator error: the chamber holds gain P + offset_pa",
                              false,
                              {{"gain", "1", 1.0, 0.5, 1.5}, {"offset_pa", "Pa", 0.0, -500.0, 500.0}},
                              [](const EffectParameterValues& v) {
                                return std::make_unique<PressureOffset>(v.at("gain"), v.at("offset_pa"));
                              }});

}  // namespace
}  // namespace hj
