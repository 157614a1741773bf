// Static equilibrium of the baseline model (docs/model.md, "Forces" and
// "States and actions"): the flat surface balances at the levelling
// pressure, the rest sag is a symmetric equilibrium, the static solver ends
// at zero net force, and the internal forces obey Newton's third law.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>
#include <string>
#include <vector>

#include "model/action.h"
#include "model/device_state.h"
#include "model/mesh.h"
#include "model/parameters.h"
#include "sim/effect_registry.h"
#include "sim/force_model.h"
#include "sim/jamming_springs.h"
#include "sim/simulator.h"
#include "sim/surface_measures.h"

namespace hj {
namespace {

const ArrayGeometry kPaper{3, 4, 0.038, 4};

double flat_residual(double pressure_factor) {
  const Mesh mesh(kPaper);
  const SurfaceParameters params = SurfaceParameters::paper_defaults(kPaper);
  const ForceModel model(mesh, params, make_baseline_effects());
  DeviceState state = DeviceState::flat(mesh);
  state.pressure_pa = pressure_factor * params.levelling_pressure_pa(mesh);
  Eigen::Matrix3Xd f;
  model.forces(state, state.x, f);
  return max_free_force(f, state.fixed_points(mesh));
}

TEST(FlatSurface, BalancesAtTheLevellingPressure) {
  EXPECT_LT(flat_residual(1.0), 1e-9);
}

TEST(FlatSurface, IsNotBalancedAboveTheLevellingPressure) {
  // 5 % too much pressure leaves 0.05 m g on every free point (~1.2e-4 N).
  EXPECT_GT(flat_residual(1.05), 1e-6);
}

TEST(RestState, SagsSymmetricallyAndConverges) {
  const Simulator sim(kPaper, SurfaceParameters::paper_defaults(kPaper));
  const Mesh& mesh = sim.mesh();
  EXPECT_TRUE(sim.last_settle().converged);
  EXPECT_LT(sim.last_settle().residual_n, 1e-9);

  const Eigen::MatrixXd z = point_heights(mesh, sim.state().x);
  const int last_i = mesh.point_rows() - 1, last_j = mesh.point_cols() - 1;
  EXPECT_LT(z(last_i / 2, last_j / 2), 0.0) << "the centre must sag under gravity";
  const std::vector<char> fixed = sim.state().fixed_points(mesh);
  for (int i = 0; i <= last_i; ++i)
    for (int j = 0; j <= last_j; ++j) {
      if (!fixed[mesh.index(i, j)]) {
        EXPECT_LE(z(i, j), 0.0) << "point (" << i << ", " << j << ")";
      }
      EXPECT_NEAR(z(i, j), z(i, last_j - j), 1e-9) << "left-right mirror of (" << i << ", " << j << ")";
      EXPECT_NEAR(z(i, j), z(last_i - i, j), 1e-9) << "up-down mirror of (" << i << ", " << j << ")";
    }
}

TEST(StaticSolver, EndsInEquilibriumAfterActions) {
  Simulator sim(kPaper, SurfaceParameters::paper_defaults(kPaper));
  for (const Action& a : {Action::set_pressure(1200.0), Action::jam(0, 1), Action::pin(1, 2),
                          Action::set_pressure(2000.0), Action::jam(2, 3), Action::unjam(0, 1)}) {
    sim.apply(a);
    Eigen::Matrix3Xd f;
    sim.model().forces(sim.state(), sim.state().x, f);
    EXPECT_LT(max_free_force(f, sim.state().fixed_points(sim.mesh())), 1e-8) << "after " << a.describe();
  }
}

// A state with every cell jammed at random rest angles and every point
// moved by up to 2 mm.
DeviceState random_jammed_state(const Mesh& mesh, std::mt19937& rng) {
  std::uniform_real_distribution<double> move(-2e-3, 2e-3), angle(-0.3, 0.3);
  DeviceState state = DeviceState::flat(mesh);
  state.pressure_pa = 1500.0;
  for (int p = 0; p < mesh.num_points(); ++p)
    for (int c = 0; c < 3; ++c) state.x(c, p) += move(rng);
  std::fill(state.cell_jammed.begin(), state.cell_jammed.end(), 1);
  for (int p = 0; p < mesh.num_points(); ++p) state.phi_eq.col(p) << angle(rng), angle(rng);
  return state;
}

TEST(InternalForces, SumToZeroForceAndTorque) {
  const Mesh mesh(kPaper);
  const SurfaceParameters params = SurfaceParameters::paper_defaults(kPaper);
  std::vector<std::unique_ptr<Effect>> internal;
  internal.push_back(EffectRegistry::instance().get("springs").make({}));
  internal.push_back(EffectRegistry::instance().get("jamming").make({}));
  const ForceModel model(mesh, params, std::move(internal));
  std::mt19937 rng(20240611);
  const DeviceState state = random_jammed_state(mesh, rng);

  Eigen::Matrix3Xd f;
  model.forces(state, state.x, f);
  const double scale = f.colwise().norm().sum();
  ASSERT_GT(scale, 1e-3) << "the perturbed state must load the springs";
  // Newton's third law: equal and opposite, so no net force ...
  const Eigen::Vector3d net = f.rowwise().sum();
  EXPECT_LT(net.norm(), 1e-12 * scale) << net.transpose();
  // ... and, being invariant under rotation, no net torque either.
  Eigen::Vector3d torque = Eigen::Vector3d::Zero();
  for (int p = 0; p < mesh.num_points(); ++p) torque += state.x.col(p).cross(f.col(p));
  EXPECT_LT(torque.norm(), 1e-12 * scale * 0.2) << torque.transpose();
  // Moving the whole device changes none of them.
  const Eigen::Matrix3Xd moved = state.x.colwise() + Eigen::Vector3d(0.05, -0.02, 0.03);
  Eigen::Matrix3Xd f_moved;
  model.forces(state, moved, f_moved);
  EXPECT_LT((f_moved - f).cwiseAbs().maxCoeff(), 1e-9 * f.cwiseAbs().maxCoeff());
}

}  // namespace
}  // namespace hj
