// Mirror symmetry (src/sim/mirror_symmetry.h): which mirrors a state keeps,
// the subspace of displacements that keep them, and the static solver's
// settle on that subspace, which must reach the full settle's equilibrium
// and still see instabilities that break the symmetry.
#include <gtest/gtest.h>

#include <random>

#include "model/action.h"
#include "sim/effect_registry.h"
#include "sim/mirror_symmetry.h"
#include "sim/simulator.h"
#include "sim/surface_measures.h"
#include "sim/divergence_mode.h"
#include "sim/symmetric_stability.h"

namespace hj {
namespace {

const ArrayGeometry kMedium{6, 8, 0.038, 4};  // 2,325 free DOFs

constexpr unsigned kMirrorX = 0b0011, kMirrorY = 0b0101, kPointReflection = 0b1001, kBoth = 0b1111;

unsigned group_after_jams(const std::vector<std::pair<int, int>>& cells) {
  Simulator sim(kMedium, SurfaceParameters::paper_defaults(kMedium));
  sim.apply(Action::set_pressure(1000.0));
  for (auto [r, c] : cells) sim.apply(Action::jam(r, c));
  return mirror_symmetry_of(sim.model(), sim.state()).elements;
}

TEST(MirrorSymmetryOf, IsTheGroupThatMapsTheJamsOntoThemselves) {
  EXPECT_EQ(group_after_jams({}), kBoth) << "a free net";
  EXPECT_EQ(group_after_jams({{0, 0}, {0, 7}, {5, 0}, {5, 7}}), kBoth) << "the four corners";
  EXPECT_EQ(group_after_jams({{0, 0}, {0, 7}}), kMirrorX) << "one row's two ends";
  EXPECT_EQ(group_after_jams({{0, 0}, {5, 0}}), kMirrorY) << "one column's two ends";
  EXPECT_EQ(group_after_jams({{0, 0}, {5, 7}}), kPointReflection) << "opposite corners";
  EXPECT_EQ(group_after_jams({{0, 0}}), 1u) << "one corner";
}

TEST(MirrorSymmetryOf, NeedsThePositionsAndTheForcesToBeMirrored) {
  Simulator sim(kMedium, SurfaceParameters::paper_defaults(kMedium));
  DeviceState state = sim.state();
  EXPECT_EQ(mirror_symmetry_of(sim.model(), state).elements, kBoth);
  // A pin on the centre node keeps every mirror; one off the centre lines none.
  state.node_pinned[sim.mesh().node_index(3, 4)] = 1;
  EXPECT_EQ(mirror_symmetry_of(sim.model(), state).elements, kBoth);
  state.node_pinned[sim.mesh().node_index(1, 1)] = 1;
  EXPECT_EQ(mirror_symmetry_of(sim.model(), state).elements, 1u);
  // A point moved by a micrometre: no longer symmetric.
  state = sim.state();
  state.x(0, sim.mesh().index(5, 9)) += 1e-6;
  EXPECT_EQ(mirror_symmetry_of(sim.model(), state).elements, 1u);
  // Symmetric positions, but a stiffness that grows along x: only the
  // mirror in y keeps the forces.
  const ForceModel graded(sim.mesh(), sim.params(), make_effects({"cell_stiffness"}, {{"cell_stiffness", {{"grad_x", 0.2}}}}));
  EXPECT_EQ(mirror_symmetry_of(graded, sim.state()).elements, kMirrorY);
}

// On the flat grid the springs carry no tension, so a stiffness gradient
// leaves the forces (gravity alone) mirrored; the stiffness is not, and a
// settle on the symmetric displacements from there failed and sent a fit's
// replay to the careful control and another equilibrium (cell_stiffness
// grad_x -0.3, 3 x 4, a replay's first settle).
TEST(MirrorSymmetryOf, NeedsTheStiffnessToBeMirroredWhereTheForcesAre) {
  const ArrayGeometry small{3, 4, 0.038, 4};
  Simulator sim(small, SurfaceParameters::paper_defaults(small));
  DeviceState flat = sim.state();
  flat.x = sim.mesh().rest_positions();
  flat.pressure_pa = 0.0;
  const ForceModel graded(sim.mesh(), sim.params(),
                          make_effects({"cell_stiffness"}, {{"cell_stiffness", {{"grad_x", -0.3}}}}));
  EXPECT_EQ(mirror_symmetry_of(graded, flat).elements, kMirrorY);
}

TEST(MirrorSubspace, IsTheSymmetricDisplacementsAndReducesKToSTKS) {
  Simulator sim(kMedium, SurfaceParameters::paper_defaults(kMedium));
  DeviceState state = sim.state();
  state.pressure_pa = 1500.0;  // K out of equilibrium, with the pressure's asymmetric part
  const std::vector<char> fixed = sim.model().fixed_points(state);
  StiffnessMatrix k(sim.mesh(), fixed, [&](StiffnessSink& s) { sim.model().add_stiffness(state, state.x, s); });
  k.set_zero();
  sim.model().add_stiffness(state, state.x, k);
  for (unsigned elements : {kBoth, kMirrorX, kPointReflection}) {
    const MirrorGroup group{elements};
    const MirrorSubspace subspace(sim.mesh(), k, group);
    // Each orbit of (point, component) under a group of n elements has n
    // members, fewer on the centre lines.
    EXPECT_GE(subspace.num_dofs(), k.num_dofs() / (group.order() + 1)) << elements;
    EXPECT_LT(subspace.num_dofs(), k.num_dofs() / (group.order() + 1) + 3 * 40) << elements;
    std::mt19937 random(7);
    std::uniform_real_distribution<double> uniform(-1.0, 1.0);
    Eigen::VectorXd y(subspace.num_dofs()), z(subspace.num_dofs());
    for (int i = 0; i < y.size(); ++i) y[i] = uniform(random), z[i] = uniform(random);
    // S y is symmetric: averaging it over the group changes nothing.
    const Eigen::Matrix3Xd moved = sim.mesh().rest_positions() + 1e-3 * subspace.scatter(y);
    EXPECT_LT((mirror_average(sim.mesh(), moved, group, fixed) - moved).cwiseAbs().maxCoeff(), 1e-15) << elements;
    // S^T S = W.
    EXPECT_LT((subspace.gather(subspace.scatter(y)) - subspace.weights().cwiseProduct(y)).cwiseAbs().maxCoeff(), 1e-12)
        << elements;
    // reduce() is S^T K S.
    Eigen::SparseMatrix<double> reduced = subspace.pattern();
    subspace.reduce(reduced);
    const Eigen::VectorXd ksy = subspace.gather(k.scatter(k.matrix() * k.gather(subspace.scatter(y))));
    EXPECT_LT((reduced * y - ksy).cwiseAbs().maxCoeff(), 1e-9 * ksy.cwiseAbs().maxCoeff()) << elements;
    // Not symmetric (pressure follows the normals), but z^T (S^T K S) y =
    // (S z)^T K (S y) all the same.
    EXPECT_NEAR(z.dot(reduced * y), z.dot(ksy), 1e-9 * std::abs(z.dot(ksy))) << elements;
  }
}

TEST(MirrorProjection, SplitsAFieldIntoOrthogonalClassesThatSumToIt) {
  const Mesh mesh(kMedium);
  std::vector<char> fixed(mesh.num_points(), 0);
  for (int p = 0; p < mesh.num_points(); ++p) fixed[p] = mesh.is_boundary(p);
  std::mt19937 random(3);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  Eigen::Matrix3Xd u(3, mesh.num_points());
  for (int p = 0; p < mesh.num_points(); ++p) u.col(p) = fixed[p] ? Eigen::Vector3d::Zero() : Eigen::Vector3d(uniform(random), uniform(random), uniform(random));
  for (unsigned elements : {kBoth, kMirrorY, kPointReflection}) {
    const MirrorGroup group{elements};
    const std::vector<unsigned> characters = mirror_characters(group);
    ASSERT_EQ(characters.size(), static_cast<size_t>(group.order() + 1));
    Eigen::Matrix3Xd sum = Eigen::Matrix3Xd::Zero(3, mesh.num_points());
    std::vector<Eigen::Matrix3Xd> parts;
    for (unsigned odd : characters) {
      parts.push_back(mirror_projection(mesh, u, group, odd, fixed));
      EXPECT_LT((mirror_projection(mesh, parts.back(), group, odd, fixed) - parts.back()).cwiseAbs().maxCoeff(), 1e-15)
          << "a projection: " << elements << " " << odd;
      sum += parts.back();
    }
    EXPECT_LT((sum - u).cwiseAbs().maxCoeff(), 1e-15) << elements;
    for (size_t a = 0; a < parts.size(); ++a)
      for (size_t b = a + 1; b < parts.size(); ++b)
        EXPECT_NEAR((parts[a].array() * parts[b].array()).sum(), 0.0, 1e-12) << elements << " " << a << " " << b;
  }
}

TEST(StillHasInMirrorClass, AgreesWithTheFullSearchOnTheLargeDomesShearMode) {
  // The 9 x 12 dome at 2 kPa: K has a real eigenvalue near -0.013 N/m, the
  // square net's shear mechanism, which is not symmetric.
  const ArrayGeometry g{9, 12, 0.038, 4};
  Simulator sim(g, SurfaceParameters::paper_defaults(g));
  sim.apply(Action::set_pressure(2000.0));
  const DeviceState& state = sim.state();
  const MirrorGroup group = mirror_symmetry_of(sim.model(), state);
  ASSERT_EQ(group.elements, kBoth);
  StiffnessMatrix k(sim.mesh(), sim.model().fixed_points(state),
                    [&](StiffnessSink& s) { sim.model().add_stiffness(state, state.x, s); });
  k.set_zero();
  sim.model().add_stiffness(state, state.x, k);
  DivergenceSearch full(k.matrix());
  const Eigen::VectorXd mode = full.mode();
  ASSERT_GT(mode.size(), 0);
  EXPECT_LT(mode.dot(k.matrix() * mode), 0.0);
  // The mode lies in one class, odd under a mirror.
  std::vector<char> fixed = sim.model().fixed_points(state);
  EXPECT_LT(mirror_projection(sim.mesh(), k.scatter(mode), group, 0, fixed).norm(), 1e-6);
  EXPECT_EQ(still_has_in_mirror_class(sim.mesh(), k, group, mode, 0.9), std::optional<bool>(true));
  EXPECT_TRUE(full.still_has(mode, 0.9));
  // A symmetric direction (the dome's own rise): no such mode in its class.
  Eigen::VectorXd rise = k.gather(state.x - sim.mesh().rest_positions());
  rise.normalize();
  EXPECT_EQ(still_has_in_mirror_class(sim.mesh(), k, group, rise, 0.9), std::optional<bool>(false));
  EXPECT_FALSE(still_has_in_mirror_class(sim.mesh(), k, group, Eigen::VectorXd::Ones(3), 0.9).value())
      << "a mode of another size";
  EXPECT_FALSE(still_has_in_mirror_class(sim.mesh(), k, MirrorGroup{}, mode, 0.9).has_value())
      << "no symmetry: the full search's question";
}

// Positions after the same actions with the symmetric settle on and off.
std::pair<Eigen::Matrix3Xd, Eigen::Matrix3Xd> settle_both_ways(const ArrayGeometry& geometry,
                                                               const std::vector<Action>& actions,
                                                               std::vector<SettleReport>* reports = nullptr) {
  Eigen::Matrix3Xd out[2];
  for (int symmetric = 0; symmetric < 2; ++symmetric) {
    SimulatorOptions options;
    options.static_options.mirror_symmetry = symmetric;
    Simulator sim(geometry, SurfaceParameters::paper_defaults(geometry), options);
    for (const Action& action : actions) {
      const SettleReport report = sim.apply(action);
      EXPECT_TRUE(report.converged) << action.describe();
      if (reports) reports->push_back(report);
    }
    out[symmetric] = sim.state().x;
  }
  return {out[0], out[1]};
}

TEST(MirrorSymmetricSettle, ReachesTheFullSettlesEquilibria) {
  // A free net across levelling, then four jammed corners and a drop: every
  // state keeps both mirrors.
  const auto [full, symmetric] = settle_both_ways(
      kMedium, {Action::set_pressure(1500.0), Action::jam(0, 0), Action::jam(0, 7), Action::jam(5, 0),
                Action::jam(5, 7), Action::set_pressure(800.0)});
  EXPECT_LT((full - symmetric).cwiseAbs().maxCoeff(), 1e-9) << "m";
  // One mirror only: a row's two end cells jammed.
  const auto [full_x, symmetric_x] = settle_both_ways(
      kMedium, {Action::set_pressure(1500.0), Action::jam(2, 0), Action::jam(2, 7), Action::set_pressure(600.0)});
  EXPECT_LT((full_x - symmetric_x).cwiseAbs().maxCoeff(), 1e-9) << "m";
}

TEST(MirrorSymmetricSettle, PushesOffASymmetricSaddleToTheFullSettlesEquilibrium) {
  // 6 x 8 rising to 280 Pa (0.93 of levelling) first reaches a creased
  // saddle (stability_test.cc); the push along its mode, which is odd under
  // a mirror, settles on the displacements that keep the other mirror, and
  // must reach the stable state the push over every DOF reaches.
  std::vector<SettleReport> reports;
  const auto [full, symmetric] = settle_both_ways(
      kMedium, {Action::set_pressure(100.0), Action::set_pressure(200.0), Action::set_pressure(280.0)}, &reports);
  ASSERT_EQ(reports.size(), 6u);
  EXPECT_GE(reports[2].restarts, 1);
  EXPECT_GE(reports[5].restarts, 1);
  EXPECT_FALSE(reports[5].marginal) << "the push reached another equilibrium";
  EXPECT_LT((full - symmetric).cwiseAbs().maxCoeff(), 1e-9) << "m";
}

TEST(MirrorSymmetricSettle, StillSeesTheModesThatBreakTheSymmetry) {
  // The 9 x 12 dome at 2 kPa has a weakly diverging shear mode, which is not
  // symmetric: the settle on the symmetric displacements converges, and the
  // check over all of them must still report it (marginal), as the full
  // settle does, on the same dome.
  std::vector<SettleReport> reports;
  const auto [full, symmetric] =
      settle_both_ways(ArrayGeometry{9, 12, 0.038, 4}, {Action::set_pressure(2000.0)}, &reports);
  ASSERT_EQ(reports.size(), 2u);
  EXPECT_TRUE(reports[0].marginal);
  EXPECT_TRUE(reports[1].marginal);
  EXPECT_LT((full - symmetric).cwiseAbs().maxCoeff(), 1e-9) << "m";
}

}  // namespace
}  // namespace hj
