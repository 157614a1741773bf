// Derivatives of the optional effects (src/sim/effects) against finite
// differences, at their defaults and at non-trivial values, on a settled,
// pressurised, partly jammed device moved off equilibrium by a random field,
// and on the flat state (where the bend angles pass through zero): each
// stiffness is minus the force Jacobian, each conservative force is minus
// the gradient of its energy.
#include <gtest/gtest.h>

#include <map>
#include <ostream>
#include <random>
#include <string>

#include "effect_checks.h"
#include "model/action.h"
#include "sim/effect_registry.h"
#include "sim/simulator.h"

namespace hj {
namespace {

const ArrayGeometry kPaper{3, 4, 0.038, 4};

struct Case {
  std::string effect;
  EffectParameterValues values;
  std::string label;   // test name suffix
  bool active = true;  // false where the values make the effect a no-op
};

void PrintTo(const Case& c, std::ostream* os) { *os << c.effect << " " << c.label; }

// Settled once for all cases: 2 kPa, three jammed cells, a pin.
const Simulator& jammed_device() {
  static const Simulator sim = [] {
    Simulator s(kPaper, SurfaceParameters::paper_defaults(kPaper));
    for (const Action& a : {Action::set_pressure(1200.0), Action::jam(0, 0), Action::jam(1, 1), Action::pin(1, 3),
                            Action::set_pressure(2000.0), Action::jam(2, 2)})
      s.apply(a);
    return s;
  }();
  return sim;
}

struct Built {
  std::unique_ptr<Effect> effect;
  std::vector<char> fixed;  // what the effect leaves fixed in `state`
};

Built build(const Case& c, const DeviceState& state) {
  const Mesh& mesh = jammed_device().mesh();
  const EffectInfo& info = EffectRegistry::instance().get(c.effect);
  Built b{info.make(resolve_parameters(info, c.values)), state.fixed_points(mesh)};
  if (b.effect->frees_boundary())
    for (int p = 0; p < mesh.num_points(); ++p)
      if (mesh.is_boundary(p)) b.fixed[p] = 0;
  return b;
}

// The jammed device moved by ~1 mm everywhere it may move (seeded), or the
// flat state (every bend angle 0) moved by `flat_sigma`, with 2 kPa and
// the same jams.
DeviceState test_state(const Case& c, bool flat, double flat_sigma, unsigned seed) {
  const Simulator& sim = jammed_device();
  DeviceState state = sim.state();
  if (flat) state.x = sim.mesh().rest_positions();
  const std::vector<char> fixed = build(c, state).fixed;
  std::mt19937 rng(seed);
  state.x = testing_support::perturbed(state.x, fixed, rng, flat ? flat_sigma : 1e-3);
  return state;
}

class OptionalEffectDerivatives : public testing::TestWithParam<Case> {};

TEST_P(OptionalEffectDerivatives, StiffnessIsMinusTheForceJacobian) {
  const Case& c = GetParam();
  for (double flat_sigma : {-1.0, 0.0, 1e-5}) {
    const bool flat = flat_sigma >= 0.0;
    SCOPED_TRACE(flat ? testing::Message() << "flat, moved by " << flat_sigma << " m" : testing::Message() << "bent");
    const DeviceState state = test_state(c, flat, flat_sigma, 7);
    const Built b = build(c, state);
    const ForceContext ctx{jammed_device().mesh(), jammed_device().params(), state};
    const auto check = testing_support::check_stiffness(*b.effect, ctx, b.fixed);
    EXPECT_LE(check.error(), 1e-5 * check.analytic.norm() + 1e-9)
        << c.effect << ": |K - K_fd| = " << check.error() << ", |K| = " << check.analytic.norm();
    if (c.active && !flat) {
      EXPECT_GT(check.analytic.norm(), 0.0) << "a switched-on effect has stiffness";
    }
  }
}

TEST_P(OptionalEffectDerivatives, ConservativeForceIsMinusTheEnergyGradient) {
  const Case& c = GetParam();
  for (double flat_sigma : {-1.0, 1e-5}) {
    const bool flat = flat_sigma >= 0.0;
    SCOPED_TRACE(flat ? "flat" : "bent");
    const DeviceState state = test_state(c, flat, flat_sigma, 11);
    const Built b = build(c, state);
    const ForceContext ctx{jammed_device().mesh(), jammed_device().params(), state};
    if (!b.effect->energy(ctx, state.x)) return;  // a follower load
    const auto check = testing_support::check_energy_gradient(*b.effect, ctx, b.fixed);
    if (c.active && !flat) {
      ASSERT_GT(check.force.norm(), 0.0);
    }
    EXPECT_LE(check.error(), 1e-6 * check.force.norm() + 1e-12)
        << c.effect << ": |F| = " << check.force.norm() << ", |F + grad E| = " << check.error();
  }
}

INSTANTIATE_TEST_SUITE_P(Effects, OptionalEffectDerivatives,
                         testing::Values(Case{"bending", {}, "default", false},
                                         Case{"bending", {{"kappa_bend", 0.002}}, "demo"},
                                         Case{"bending", {{"kappa_bend", 0.5}}, "stiff"},
                                         Case{"stiffening", {}, "default", false},
                                         Case{"stiffening", {{"beta", 200.0}}, "strong"},
                                         Case{"jam_contraction", {}, "default", false},
                                         Case{"jam_contraction", {{"contraction", 0.05}}, "five_percent"},
                                         Case{"cell_stiffness", {}, "default", false},
                                         Case{"cell_stiffness", {{"grad_x", 0.2}, {"grad_y", -0.1}, {"bulge", 0.3}},
                                              "field"},
                                         Case{"cell_defect", {}, "default", false},
                                         Case{"cell_defect", {{"factor", 0.4}, {"row", 1}, {"col", 1}}, "soft"},
                                         Case{"cell_defect", {{"factor", 3.0}, {"row", 0}, {"col", 2}}, "stiff"},
                                         Case{"area_pressure", {}, "default"},
                                         Case{"area_pressure", {{"weight", 0.4}}, "partial"},
                                         Case{"boundary_compliance", {}, "default"},
                                         Case{"boundary_compliance", {{"k_edge", 50.0}}, "soft"},
                                         Case{"pressure_offset", {}, "default", false},
                                         Case{"pressure_offset", {{"gain", 1.1}, {"offset_pa", -80.0}}, "gain_offset"},
                                         Case{"sensor_tilt", {{"tilt_x_mrad", 5.0}}, "no_forces", false},
                                         Case{"jam_creep", {{"creep_per_settle", 0.3}}, "no_forces", false}),
                         [](const testing::TestParamInfo<Case>& info) {
                           return info.param.effect + "_" + info.param.label;
                         });

}  // namespace
}  // namespace hj
