// Chamber pressure on every free point: F = P A_spp n, with the flat area
// per point A_spp = (R s)(C s) / N and the Eq. 3 normal
//   n = normalize((x[i][j+1] - x[i][j-1]) x (x[i+1][j] - x[i-1][j])).
// A follower load: not the gradient of an energy, so its stiffness is not
// symmetric.
#include "sim/effect_registry.h"
#include "sim/normal_load.h"

namespace hj {
namespace {

class Pressure final : public Effect {
 public:
  std::string_view name() const override { return "pressure"; }

  void add_forces(const ForceContext& ctx, const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& f) const override {
    add_normal_load(ctx.mesh, x, ctx.state.pressure_pa * ctx.mesh.area_per_point(), f);
  }

  void add_stiffness(const ForceContext& ctx, const Eigen::Matrix3Xd& x, StiffnessSink& sink) const override {
    add_normal_load_stiffness(ctx.mesh, x, ctx.state.pressure_pa * ctx.mesh.area_per_point(), sink);
  }
};

HJ_REGISTER_EFFECT(EffectInfo{"pressure", "chamber pressure P A_spp along the Eq. 3 normal", true, {},
                              [](const EffectParameterValues&) { return std::make_unique<Pressure>(); }});

}  // namespace
}  // namespace hj
