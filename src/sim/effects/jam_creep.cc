// Creep of a jam (the paper's compliance, Eq. 10, docs/model.md "Jamming"):
// the grains of a jammed cell slowly yield, so its rest bend angles move
// toward the current ones. The paper moves phi_eq by a fixed fraction every
// integration step, which ties creep to the time step; the simulator
// settles statically and session steps carry no duration, so here the unit
// of time is one settle: after each settle (Effect::after_settle)
//   phi_eq += creep_per_settle (phi - phi_eq)
// at both springs of every interior point of every jammed cell, and the
// surface settles once more under the relaxed jam. No forces of its own;
// 0 is the baseline's perfect jam.
#include <cmath>

#include "sim/effect_registry.h"
#include "sim/jamming_springs.h"

namespace hj {
namespace {

class JamCreep final : public Effect {
 public:
  explicit JamCreep(double rate) : rate_(rate) {}
  std::string_view name() const override { return "jam_creep"; }

  void add_forces(const ForceContext&, const Eigen::Matrix3Xd&, Eigen::Matrix3Xd&) const override {}
  void add_stiffness(const ForceContext&, const Eigen::Matrix3Xd&, StiffnessSink&) const override {}
  std::optional<double> energy(const ForceContext&, const Eigen::Matrix3Xd&) const override { return 0.0; }

  bool after_settle(const Mesh& mesh, const SurfaceParameters&, DeviceState& state) const override {
    if (rate_ == 0.0) return false;
    bool changed = false;
    for_each_jammed_spring(mesh, state, [&](const BendSpring& s) {
      const double step = rate_ * (bend_angle_of(state.x, s) - s.phi_eq);
      if (std::abs(step) < 1e-12) return;  // rad: nothing left to creep
      state.phi_eq(s.axis, s.p[kBendI]) += step;
      changed = true;
    });
    return changed;
  }

 private:
  double rate_;
};

HJ_REGISTER_EFFECT(EffectInfo{"jam_creep",
                              "a jam yields: after each settle phi_eq moves toward phi by creep_per_settle",
                              false,
                              {{"creep_per_settle", "1/settle", 0.0, 0.0, 1.0}},
                              [](const EffectParameterValues& v) {
                                return std::make_unique<JamCreep>(v.at("creep_per_settle"));
                              }});

}  // namespace
}  // namespace hj
