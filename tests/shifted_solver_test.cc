// The static solver's linear solve: the iterative path (large shift) and the
// LU path (small shift) both solve (K + mu I) dx = r, on a system big enough
// to take the iterative path.
#include <gtest/gtest.h>

#include <Eigen/SparseLU>

#include "sim/shifted_solver.h"
#include "sim/simulator.h"
#include "sim/stiffness_matrix.h"

namespace hj {
namespace {

TEST(ShiftedSolver, IterativeAndDirectPathsSolveTheSameSystem) {
  const ArrayGeometry geometry{6, 8, 0.038, 4};  // 2,325 free DOFs
  SimulatorOptions options;
  Simulator sim(geometry, SurfaceParameters::paper_defaults(geometry), options);
  DeviceState state = sim.state();
  state.pressure_pa = 2000.0;  // out of equilibrium: a real Newton right-hand side
  const auto fixed = state.fixed_points(sim.mesh());
  StiffnessMatrix k(sim.mesh(), fixed, [&](StiffnessSink& s) { sim.model().add_stiffness(state, state.x, s); });
  Eigen::Matrix3Xd f;
  sim.model().forces(state, state.x, f);
  const Eigen::VectorXd r = k.gather(f);
  ASSERT_GE(k.num_dofs(), 1500);

  ShiftedSolver solver;
  for (const double mu : {50.0, 1e-3}) {
    k.set_zero();
    sim.model().add_stiffness(state, state.x, k);
    for (int p : k.free_points()) k.add(p, p, mu * Eigen::Matrix3d::Identity());
    Eigen::VectorXd dx;
    ASSERT_TRUE(solver.solve(k.matrix(), mu, r, dx)) << "mu " << mu;
    Eigen::SparseLU<Eigen::SparseMatrix<double>> lu(k.matrix());
    const Eigen::VectorXd exact = lu.solve(r);
    EXPECT_LT((dx - exact).norm(), 1e-6 * exact.norm()) << "mu " << mu;
    EXPECT_LT((k.matrix() * dx - r).norm(), 1e-7 * r.norm()) << "mu " << mu;
  }
  // The heavily shifted system went the cheap way, the nearly unshifted one
  // needed the LU.
  EXPECT_EQ(solver.iterative_solves(), 1);
  EXPECT_EQ(solver.direct_solves(), 1);
}

}  // namespace
}  // namespace hj
