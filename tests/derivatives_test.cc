// Derivatives of the baseline effects against finite differences: each
// effect's analytic stiffness is minus the Jacobian of its force, each
// conservative effect's force is minus the gradient of its energy, and the
// signed bend angle of a jamming spring is smooth through the flat state
// (docs/model.md, "Jamming").
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <random>
#include <string>

#include "model/action.h"
#include "sim/bend_angle.h"
#include "sim/effect_registry.h"
#include "sim/force_model.h"
#include "sim/simulator.h"
#include "sim/stiffness_matrix.h"
#include "effect_checks.h"

namespace hj {
namespace {

const ArrayGeometry kPaper{3, 4, 0.038, 4};

// A settled, pressurised device with three jammed cells and a pin, every
// free point then moved by a seeded random field of ~1 mm, so that springs
// are stretched unevenly and jammed cells sit away from their rest angles.
DeviceState perturbed_jammed_state(const Simulator& sim, std::mt19937& rng) {
  DeviceState state = sim.state();
  state.x = testing_support::perturbed(state.x, state.fixed_points(sim.mesh()), rng);
  return state;
}

Simulator settled_jammed_device() {
  Simulator sim(kPaper, SurfaceParameters::paper_defaults(kPaper));
  for (const Action& a : {Action::set_pressure(1200.0), Action::jam(0, 0), Action::jam(1, 1), Action::pin(1, 3),
                          Action::set_pressure(2000.0), Action::jam(2, 2)})
    sim.apply(a);
  return sim;
}

const Effect& effect_named(const ForceModel& model, const std::string& name) {
  for (const auto& e : model.effects())
    if (e->name() == name) return *e;
  throw std::logic_error("no effect " + name);
}

class EffectDerivatives : public testing::TestWithParam<const char*> {};

TEST_P(EffectDerivatives, StiffnessIsMinusTheForceJacobian) {
  const Simulator sim = settled_jammed_device();
  std::mt19937 rng(7);
  const DeviceState state = perturbed_jammed_state(sim, rng);
  const Mesh& mesh = sim.mesh();
  const Effect& effect = effect_named(sim.model(), GetParam());
  const ForceContext ctx{mesh, sim.params(), state};
  const auto check = testing_support::check_stiffness(effect, ctx, state.fixed_points(mesh));
  EXPECT_LE(check.error(), 1e-5 * check.analytic.norm())
      << GetParam() << ": |K - K_fd| = " << check.error() << ", |K| = " << check.analytic.norm();
  if (std::string(GetParam()) == "gravity") {
    EXPECT_EQ(check.numeric.norm(), 0.0) << "a constant weight has no stiffness";
  } else {
    EXPECT_GT(check.analytic.norm(), 0.0);
  }
}

TEST_P(EffectDerivatives, ConservativeForceIsMinusTheEnergyGradient) {
  const Simulator sim = settled_jammed_device();
  std::mt19937 rng(11);
  const DeviceState state = perturbed_jammed_state(sim, rng);
  const Mesh& mesh = sim.mesh();
  const Effect& effect = effect_named(sim.model(), GetParam());
  const ForceContext ctx{mesh, sim.params(), state};
  if (!effect.energy(ctx, state.x)) {
    EXPECT_EQ(std::string(GetParam()), "pressure") << "only the follower load has no energy";
    return;
  }
  const auto check = testing_support::check_energy_gradient(effect, ctx, state.fixed_points(mesh));
  ASSERT_GT(check.force.norm(), 0.0);
  EXPECT_LE(check.error(), 1e-6 * check.force.norm())
      << GetParam() << ": |F| = " << check.force.norm() << ", |F + grad E| = " << check.error();
}

INSTANTIATE_TEST_SUITE_P(Baseline, EffectDerivatives, testing::Values("springs", "gravity", "pressure", "jamming"),
                         [](const testing::TestParamInfo<const char*>& info) { return std::string(info.param); });

// --- The bend angle through the flat state -------------------------------

constexpr double kH = 0.0095;  // paper mesh spacing, m

struct BendPoints {
  std::array<Eigen::Vector3d, 5> x;  // A, i, B, C1, C2
  double sigma;
};

// A straight line A, i, B along x (sigma +1) or y (sigma -1), cross
// neighbours C1, C2 in the plane z = 0, and i lifted by z.
BendPoints line_through(double z, int axis) {
  const Eigen::Vector3d along = axis == 0 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  const Eigen::Vector3d across = axis == 0 ? Eigen::Vector3d::UnitY() : Eigen::Vector3d::UnitX();
  return {{Eigen::Vector3d(-kH * along), Eigen::Vector3d(z * Eigen::Vector3d::UnitZ()), Eigen::Vector3d(kH * along),
           Eigen::Vector3d(-kH * across), Eigen::Vector3d(kH * across)},
          axis == 0 ? 1.0 : -1.0};
}

double phi_of(const BendPoints& b) { return bend_angle(b.x[0], b.x[1], b.x[2], b.x[3], b.x[4], b.sigma); }

// Largest relative error of bend_angle_gradient against central differences
// of bend_angle over all 15 coordinates.
void expect_gradient_matches(BendPoints b) {
  const auto g = bend_angle_gradient<double>(b.x[0], b.x[1], b.x[2], b.x[3], b.x[4], b.sigma);
  double g_norm = 0.0, err = 0.0;
  const double eps = 1e-7;
  for (int k = 0; k < 5; ++k)
    for (int c = 0; c < 3; ++c) {
      ASSERT_TRUE(std::isfinite(g[k][c])) << "point " << k << " coordinate " << c;
      const double x0 = b.x[k][c];
      b.x[k][c] = x0 + eps;
      const double plus = phi_of(b);
      b.x[k][c] = x0 - eps;
      const double minus = phi_of(b);
      b.x[k][c] = x0;
      const double fd = (plus - minus) / (2.0 * eps);
      err = std::max(err, std::abs(g[k][c] - fd));
      g_norm = std::max(g_norm, std::abs(g[k][c]));
    }
  EXPECT_GT(g_norm, 0.5 / kH);  // lifting i by dz bends by about 2 dz / h
  EXPECT_LE(err, 1e-6 * g_norm) << "max |grad - fd| = " << err;
}

TEST(BendAngle, IsSignedFiniteAndContinuousThroughFlat) {
  const double dz = 1e-4;
  for (int axis : {0, 1}) {
    SCOPED_TRACE(axis == 0 ? "spring along x" : "spring along y");
    const double down = phi_of(line_through(-dz, axis));
    const double flat = phi_of(line_through(0.0, axis));
    const double up = phi_of(line_through(dz, axis));
    ASSERT_TRUE(std::isfinite(down) && std::isfinite(flat) && std::isfinite(up));
    EXPECT_EQ(flat, 0.0);
    EXPECT_GT(up, 0.0) << "bulging up along the normal is positive";
    EXPECT_LT(down, 0.0);
    EXPECT_NEAR(up, -down, 1e-12) << "continuous and odd through the flat state";
    EXPECT_NEAR(up, 2.0 * std::atan(dz / kH), 1e-12);
  }
}

TEST(BendAngle, GradientMatchesFiniteDifferencesThroughFlat) {
  for (int axis : {0, 1})
    for (double z : {-1e-4, 0.0, 1e-4}) {
      SCOPED_TRACE(testing::Message() << "axis " << axis << ", z = " << z);
      expect_gradient_matches(line_through(z, axis));
    }
}

TEST(BendAngle, GradientMatchesFiniteDifferencesAtRandomShapes) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> move(-0.3 * kH, 0.3 * kH);
  for (int trial = 0; trial < 20; ++trial) {
    BendPoints b = line_through(0.0, trial % 2);
    for (auto& p : b.x)
      for (int c = 0; c < 3; ++c) p[c] += move(rng);
    SCOPED_TRACE(testing::Message() << "trial " << trial);
    expect_gradient_matches(b);
  }
}

// The jamming effect on the real mesh: a jammed flat cell whose interior
// point is lifted through the flat state feels a finite restoring force
// that is exactly zero at flat and equals -grad E on both sides.
TEST(JammingForce, RestoresThroughTheFlatState) {
  const Mesh mesh(kPaper);
  const SurfaceParameters params = SurfaceParameters::paper_defaults(kPaper);
  std::vector<std::unique_ptr<Effect>> effects;
  effects.push_back(EffectRegistry::instance().get("jamming").make({}));
  const ForceModel model(mesh, params, std::move(effects));
  DeviceState state = DeviceState::flat(mesh);
  state.cell_jammed[mesh.cell_index(1, 1)] = 1;  // phi_eq = 0: jammed flat
  const int centre = mesh.index(6, 6);           // middle of cell (1, 1)
  ASSERT_EQ(mesh.cell_of(centre), mesh.cell_index(1, 1));

  for (double z : {-1e-4, 0.0, 1e-4}) {
    SCOPED_TRACE(testing::Message() << "z = " << z);
    Eigen::Matrix3Xd x = state.x, f;
    x(2, centre) = z;
    model.forces(state, x, f);
    ASSERT_TRUE(f.allFinite());
    if (z == 0.0) {
      EXPECT_EQ(f.cwiseAbs().maxCoeff(), 0.0);
    } else {
      EXPECT_LT(f(2, centre) * z, 0.0) << "the jam pushes the point back to flat";
    }
    const double eps = 1e-8;
    for (int c = 0; c < 3; ++c) {
      Eigen::Matrix3Xd xp = x, xm = x;
      xp(c, centre) += eps;
      xm(c, centre) -= eps;
      const double fd = -(model.conservative_energy(state, xp) - model.conservative_energy(state, xm)) / (2 * eps);
      EXPECT_NEAR(f(c, centre), fd, 1e-6 * std::max(1.0, std::abs(f(2, centre))) + 1e-9) << "component " << c;
    }
  }
}

}  // namespace
}  // namespace hj
