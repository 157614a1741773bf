// A planner's session on the 9 x 12 array (tests/bench/settle_bench.cc,
// BM_SettleJamPinSession): rest, 2 kPa, the centre cell jammed, a node of it
// pinned, 2.5 kPa. Its last settle is a snap-through: the jammed, pinned
// dome's branch of equilibria ends at a fold near 2.18 kPa, so there is no
// equilibrium near the 2 kPa state, and the surface moves up to 77 mm to
// the one the paper's explicit Euler reaches. The static path (fast control,
// then the implicit flow, then the polish) must end there, stable, within
// a bounded number of solver steps.
#include <gtest/gtest.h>

#include "model/action.h"
#include "sim/divergence_mode.h"
#include "sim/simulator.h"
#include "sim/stiffness_matrix.h"

namespace hj {
namespace {

// Steps (fast control, flow and polish together, SettleReport::iterations)
// the 2 to 2.5 kPa settle may take; it takes 153.
constexpr int kMaxSnapSteps = 160;

struct ExplicitPoint {
  int row, col;
  double x, y, z;  // m
};

// Where the paper's explicit Euler (SolverKind::kExplicit, the same session)
// leaves these points at 2.5 kPa: the centre, the point that moves most in
// the snap, another far from the plate, and the far corner of the jammed
// cell, whose near corner is pinned.
constexpr ExplicitPoint kExplicitEuler[] = {
    {18, 24, 0.2280338438895, 0.1822774014197, 0.1591390567926},
    {12, 7, 0.07398662097629, 0.1278969765942, -0.001211189032341},
    {19, 4, 0.04036778864187, 0.2086460372302, -0.01725712075179},
    {20, 28, 0.3305263452051, 0.2357323014582, 0.1301575344244},
};

TEST(JamPinSnap, TheNineByTwelveSessionEndsWhereExplicitEulerDoesWithinItsStepBound) {
  const ArrayGeometry geometry{9, 12, 0.038, 4};
  Simulator sim(geometry, SurfaceParameters::paper_defaults(geometry));
  sim.apply(Action::set_pressure(2000.0));
  sim.apply(Action::jam(geometry.rows / 2, geometry.cols / 2));
  sim.apply(Action::pin(geometry.rows / 2, geometry.cols / 2));
  const Eigen::Matrix3Xd before = sim.state().x;

  const SettleReport report = sim.apply(Action::set_pressure(2500.0));
  std::printf("2 to 2.5 kPa: %d steps, %.2f s\n", report.iterations, report.seconds);
  ASSERT_TRUE(report.converged);
  EXPECT_LT(report.residual_n, 1e-9);
  EXPECT_LE(report.iterations, kMaxSnapSteps);
  // A snap, not a small step: a real test of the path.
  EXPECT_GT((sim.state().x - before).colwise().norm().maxCoeff(), 0.050);

  // Stable: no real negative eigenvalue of K, and not accepted as marginal.
  EXPECT_FALSE(report.marginal);
  const DeviceState& state = sim.state();
  StiffnessMatrix k(sim.mesh(), sim.model().fixed_points(state),
                    [&](StiffnessSink& s) { sim.model().add_stiffness(state, state.x, s); });
  EXPECT_EQ(divergence_mode(k.matrix()).size(), 0);

  for (const ExplicitPoint& p : kExplicitEuler) {
    const Eigen::Vector3d at = state.x.col(sim.mesh().index(p.row, p.col));
    EXPECT_LT((at - Eigen::Vector3d(p.x, p.y, p.z)).norm(), 1e-6)
        << "point (" << p.row << ", " << p.col << ") is " << (at - Eigen::Vector3d(p.x, p.y, p.z)).norm() * 1000
        << " mm from explicit Euler's";
  }
}

}  // namespace
}  // namespace hj
