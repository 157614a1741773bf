// The static solver's stability test and its start across the levelling
// pressure (src/sim/divergence_mode.h, src/sim/levelling_crossing.h): a
// real negative eigenvalue of K is a divergence, a negative one of sym(K)
// alone is not; crossing levelling from the mirrored start ends on the same
// dome as the settle that crawls there from the sag.
#include <gtest/gtest.h>

#include <Eigen/SparseCore>
#include <cmath>
#include <memory>
#include <utility>
#include <vector>

#include "model/action.h"
#include "sim/divergence_mode.h"
#include "sim/levelling_crossing.h"
#include "sim/simulator.h"
#include "sim/static_solver.h"
#include "sim/stiffness_matrix.h"
#include "sim/surface_measures.h"

namespace hj {
namespace {

Eigen::SparseMatrix<double> sparse(const Eigen::Matrix3d& dense) { return dense.sparseView(); }

TEST(DivergenceMode, NoneForAPositiveDefiniteStiffness) {
  EXPECT_EQ(divergence_mode(sparse(Eigen::Vector3d(2.0, 1.0, 0.5).asDiagonal())).size(), 0);
}

TEST(DivergenceMode, FindsTheNegativeDirectionOfASaddle) {
  const Eigen::VectorXd mode = divergence_mode(sparse(Eigen::Vector3d(2.0, 1.0, -0.5).asDiagonal()));
  ASSERT_EQ(mode.size(), 3);
  EXPECT_NEAR(std::abs(mode(2)), 1.0, 1e-9);
  EXPECT_NEAR(mode.head<2>().norm(), 0.0, 1e-9);
}

TEST(DivergenceMode, FindsAnInPlaneNegativeDirectionToo) {
  const Eigen::VectorXd mode = divergence_mode(sparse(Eigen::Vector3d(-0.5, 1.0, 2.0).asDiagonal()));
  ASSERT_EQ(mode.size(), 3);
  EXPECT_NEAR(std::abs(mode(0)), 1.0, 1e-9);
}

TEST(DivergenceMode, ANegativeEigenvalueOfSymKAloneIsNotADivergence) {
  // K's eigenvalues are all 1 (stable), sym(K) = [[1,2],[2,1]] has -1: a
  // follower load's asymmetry, as on a large pressurised dome.
  Eigen::Matrix3d k;
  k << 1.0, 4.0, 0.0,  //
      0.0, 1.0, 0.0,   //
      0.0, 0.0, 1.0;
  EXPECT_EQ(divergence_mode(sparse(k)).size(), 0);
}

TEST(DivergenceSearch, AsksAboutAKnownModeAndAgreesWithTheFullSearch) {
  const Eigen::SparseMatrix<double> saddle = sparse(Eigen::Vector3d(2.0, 1.0, -0.5).asDiagonal());
  const Eigen::Vector3d near_mode = Eigen::Vector3d(0.1, 0.1, 1.0).normalized();
  DivergenceSearch search(saddle);
  EXPECT_TRUE(search.still_has(near_mode, 0.9)) << "inverse iteration from near the mode";
  EXPECT_FALSE(search.still_has(Eigen::Vector3d(1.0, 0.0, 0.0), 0.9)) << "a stable direction stays stable";
  EXPECT_FALSE(search.still_has(Eigen::Vector2d(0.0, 1.0), 0.9)) << "a mode of another size";
  EXPECT_EQ(search.mode(), divergence_mode(saddle));
  const Eigen::SparseMatrix<double> definite = sparse(Eigen::Vector3d(2.0, 1.0, 0.5).asDiagonal());
  DivergenceSearch stable(definite);
  EXPECT_FALSE(stable.still_has(Eigen::Vector3d(0.0, 0.0, 1.0), 0.9));
  EXPECT_EQ(stable.mode().size(), 0);
}

const ArrayGeometry kPaper{3, 4, 0.038, 4};

TEST(LevellingCrossing, OnlyForAFreeNetWhoseLoadChangesSign) {
  Simulator sim(kPaper, SurfaceParameters::paper_defaults(kPaper));
  const double levelling = sim.params().levelling_pressure_pa(sim.mesh());
  EXPECT_TRUE(levelling_crossing_start(sim.model(), sim.state(), 2000.0).has_value());
  EXPECT_FALSE(levelling_crossing_start(sim.model(), sim.state(), 0.9 * levelling).has_value());
  sim.apply(Action::jam(1, 1));
  EXPECT_FALSE(levelling_crossing_start(sim.model(), sim.state(), 2000.0).has_value()) << "a jammed cell";
  sim.apply(Action::unjam(1, 1));
  sim.apply(Action::pin(1, 1));
  EXPECT_FALSE(levelling_crossing_start(sim.model(), sim.state(), 2000.0).has_value()) << "a pinned node";
}

TEST(LevellingCrossing, EndsOnTheDomeTheSettleFromTheSagReaches) {
  Simulator sim(kPaper, SurfaceParameters::paper_defaults(kPaper));
  DeviceState from_sag = sim.state();
  from_sag.pressure_pa = 2000.0;
  ASSERT_TRUE(settle_static(sim.model(), from_sag).converged);
  sim.apply(Action::set_pressure(2000.0));
  const Eigen::MatrixXd a = point_heights(sim.mesh(), sim.state().x), b = point_heights(sim.mesh(), from_sag.x);
  EXPECT_GT(a.maxCoeff(), 0.05) << "a dome, not the sag";
  EXPECT_LT((a - b).cwiseAbs().maxCoeff(), 1e-5) << "m";
}

// K = -dF/dx over the free points of a settled state.
Eigen::SparseMatrix<double> stiffness_at(const Simulator& sim) {
  const DeviceState& state = sim.state();
  StiffnessMatrix k(sim.mesh(), sim.model().fixed_points(state),
                    [&](StiffnessSink& sink) { sim.model().add_stiffness(state, state.x, sink); });
  k.set_zero();
  sim.model().add_stiffness(state, state.x, k);
  return k.matrix();
}

TEST(CreasedSag, ThePushLeavesTheSaddleForAStableEquilibrium) {
  // 6 x 8 rising from the sag to 280 Pa (0.93 of levelling): the settle
  // first reaches a creased saddle (K has a real eigenvalue near -0.06
  // N/m). model.md: the solver must move on to the stable state beside it.
  const ArrayGeometry g{6, 8, 0.038, 4};
  auto rise = [&](bool check_stability) {
    SimulatorOptions options;
    options.fallback_max_steps = 1;
    options.static_options.check_stability = check_stability;
    auto sim = std::make_unique<Simulator>(g, SurfaceParameters::paper_defaults(g), options);
    for (double p : {100.0, 200.0}) sim->apply(Action::set_pressure(p));
    const SettleReport report = sim->apply(Action::set_pressure(280.0));
    return std::make_pair(std::move(sim), report);
  };
  const auto [saddle, unchecked] = rise(false);
  ASSERT_TRUE(unchecked.converged);
  EXPECT_GT(divergence_mode(stiffness_at(*saddle)).size(), 0) << "without the check the settle stops on the saddle";

  const auto [stable, report] = rise(true);
  ASSERT_TRUE(report.converged);
  EXPECT_GE(report.restarts, 1);
  EXPECT_FALSE(report.marginal) << "the push reached another equilibrium";
  EXPECT_LT(report.residual_n, 1e-9);
  EXPECT_EQ(divergence_mode(stiffness_at(*stable)).size(), 0) << "and it is stable";
  const double moved = (stable->state().x - saddle->state().x).cwiseAbs().maxCoeff();
  EXPECT_GT(moved, 1e-4) << "m: a different surface, not the saddle again";
}

TEST(LargeDome, SettlesFromRestTo2kPaAndAcceptsItsSlowShearMode) {
  // 9 x 12 at 2 kPa: the springs stretch ~3.6 x and K has a real eigenvalue
  // near -0.013 N/m (the square net's shear mechanism under a follower
  // load). A push along it leads nowhere within the budget, so the settle
  // ends on the equilibrium, reported marginal, instead of drifting.
  const ArrayGeometry g{9, 12, 0.038, 4};
  Simulator sim(g, SurfaceParameters::paper_defaults(g));
  const SettleReport& report = sim.apply(Action::set_pressure(2000.0));
  EXPECT_TRUE(report.converged);
  EXPECT_TRUE(report.marginal);
  EXPECT_LT(report.residual_n, 1e-9);
  const Eigen::MatrixXd z = point_heights(sim.mesh(), sim.state().x);
  EXPECT_NEAR(z(18, 24), 0.167, 0.001) << "centre height, m (explicit Euler: 0.16695)";
}

TEST(CreasedSag, WithTwelveJammedCellsSettlesStatically) {
  // 6 x 8 sagging at 0.8 of levelling with a dozen cells jammed, then 0.96
  // of it, where the sagging net creases. With rho in the plain norm the
  // careful steps stalled (1000 steps; the explicit fallback then needed
  // 516,713, the curved rescue 434 more); in the compliance-weighted norm
  // they settle (235). Fallback off, so only the static solver can pass.
  const ArrayGeometry g{6, 8, 0.038, 4};
  SimulatorOptions options;
  options.fallback_max_steps = 1;
  Simulator sim(g, SurfaceParameters::paper_defaults(g), options);
  for (double p : {50.0, 100.0, 150.0}) sim.apply(Action::set_pressure(p));
  for (auto [r, c] : std::vector<std::pair<int, int>>{
           {0, 0}, {0, 7}, {5, 0}, {5, 7}, {1, 2}, {2, 5}, {3, 3}, {4, 1}, {2, 1}, {3, 6}, {1, 5}, {4, 4}})
    sim.apply(Action::jam(r, c));
  for (double p : {200.0, 250.0}) sim.apply(Action::set_pressure(p));
  const SettleReport& report = sim.apply(Action::set_pressure(300.0));
  EXPECT_TRUE(report.converged);
  EXPECT_LT(report.residual_n, 1e-9);
  EXPECT_FALSE(report.marginal);
}

TEST(JammedSag, CarefulStepsSettleItAndAgreeWithExplicitEuler) {
  // All twelve cells jammed at 295 Pa, then 0 Pa: the jammed net turns as
  // rigid-ish plates on soft springs. The careful control alone (no fast
  // pass, no fallback) must settle it in its compliance-weighted norm
  // within 100 steps (58 measured; 158 in the plain norm), on the surface
  // the paper's explicit Euler reaches.
  auto run = [](SolverKind solver) {
    SimulatorOptions options;
    options.solver = solver;
    options.fallback_max_steps = 1;
    options.static_options.fast_iterations = 0;
    options.static_options.max_iterations = 100;
    Simulator sim(kPaper, SurfaceParameters::paper_defaults(kPaper), options);
    sim.apply(Action::set_pressure(590.0));
    sim.apply(Action::set_pressure(295.0));
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 4; ++c) sim.apply(Action::jam(r, c));
    const SettleReport& report = sim.apply(Action::set_pressure(0.0));
    EXPECT_TRUE(report.converged);
    return point_heights(sim.mesh(), sim.state().x);
  };
  const Eigen::MatrixXd fast = run(SolverKind::kStatic), reference = run(SolverKind::kExplicit);
  EXPECT_NEAR(fast(6, 8), -0.0345, 0.0005) << "centre, m";
  EXPECT_LT((fast - reference).cwiseAbs().maxCoeff(), 1e-5) << "m";
}

}  // namespace
}  // namespace hj
