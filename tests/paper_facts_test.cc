// Behaviour of the paper's 3 x 4 device that the paper reports or the model
// promises (docs/model.md, "States and actions"): pressure lifts the
// surface, jamming holds a cell's bend, pins hold nodes, the result depends
// on the order of actions, repeats change nothing, and both solvers agree.
#include <gtest/gtest.h>

#include <chrono>
#include <iostream>
#include <vector>

#include "model/action.h"
#include "sim/simulator.h"
#include "sim/surface_measures.h"

namespace hj {
namespace {

const ArrayGeometry kPaper{3, 4, 0.038, 4};

// The paper device, levelled from above (0.6 kPa, then 0.31 kPa, just
// above the levelling pressure of 0.301 kPa).
Simulator levelled_device() {
  Simulator sim(kPaper, SurfaceParameters::paper_defaults(kPaper));
  sim.apply(Action::set_pressure(600.0));
  sim.apply(Action::set_pressure(310.0));
  return sim;
}

// The paper device inflated from rest straight to `pa`, well above levelling.
Simulator inflated_device(double pa) {
  Simulator sim(kPaper, SurfaceParameters::paper_defaults(kPaper));
  sim.apply(Action::set_pressure(pa));
  return sim;
}

double max_height_difference(const Mesh& mesh, const Eigen::Matrix3Xd& a, const Eigen::Matrix3Xd& b) {
  return (point_heights(mesh, a) - point_heights(mesh, b)).cwiseAbs().maxCoeff();
}

TEST(PaperDevice, RisingPressureNeverLowersANodeOrAnUnjammedCell) {
  Simulator sim = levelled_device();
  const Mesh& mesh = sim.mesh();
  Eigen::MatrixXd nodes = node_heights(mesh, sim.state().x);
  Eigen::MatrixXd curvature = cell_curvatures(mesh, sim.state().x);
  for (double pa : {400.0, 800.0, 1200.0, 2000.0, 3000.0}) {
    sim.apply(Action::set_pressure(pa));
    SCOPED_TRACE(testing::Message() << pa << " Pa");
    const Eigen::MatrixXd nodes_now = node_heights(mesh, sim.state().x);
    const Eigen::MatrixXd curvature_now = cell_curvatures(mesh, sim.state().x);
    for (int a = 0; a < nodes.rows(); ++a)
      for (int b = 0; b < nodes.cols(); ++b)
        EXPECT_GE(nodes_now(a, b), nodes(a, b) - 1e-9) << "node (" << a + 1 << ", " << b + 1 << ")";
    for (int r = 0; r < mesh.rows(); ++r)
      for (int c = 0; c < mesh.cols(); ++c)
        EXPECT_GE(curvature_now(r, c), curvature(r, c) - 1e-9) << "cell (" << r << ", " << c << ")";
    EXPECT_GT(curvature_now(1, 1), curvature(1, 1)) << "more pressure must bulge a free cell further";
    nodes = nodes_now;
    curvature = curvature_now;
  }
}

TEST(PaperDevice, JammedCellHoldsItsBend) {
  // Cells (1, 1) and (1, 2) are mirror images of each other; jam only (1, 1).
  Simulator jammed = inflated_device(1000.0);
  jammed.apply(Action::jam(1, 1));
  Simulator unjammed = inflated_device(1000.0);
  const Eigen::MatrixXd before = cell_curvatures(jammed.mesh(), jammed.state().x);
  const Eigen::MatrixXd before_free = cell_curvatures(unjammed.mesh(), unjammed.state().x);

  jammed.apply(Action::set_pressure(2000.0));
  unjammed.apply(Action::set_pressure(2000.0));
  const Eigen::MatrixXd after = cell_curvatures(jammed.mesh(), jammed.state().x);
  const Eigen::MatrixXd after_free = cell_curvatures(unjammed.mesh(), unjammed.state().x);

  const double jammed_change = std::abs(after(1, 1) - before(1, 1));
  const double neighbour_change = std::abs(after(1, 2) - before(1, 2));
  const double unjammed_run_change = std::abs(after_free(1, 1) - before_free(1, 1));
  EXPECT_GT(unjammed_run_change, 0.0);
  EXPECT_LT(jammed_change, 0.2 * neighbour_change) << "against the unjammed mirror cell in the same run";
  EXPECT_LT(jammed_change, 0.2 * unjammed_run_change) << "against the same cell left unjammed";
}

TEST(PaperDevice, PinnedNodeDoesNotMove) {
  Simulator sim = inflated_device(1000.0);
  sim.apply(Action::pin(1, 1));
  const int node = sim.mesh().node_point(1, 1);
  const Eigen::Vector3d held = sim.state().x.col(node);
  const Eigen::Matrix3Xd start = sim.state().x;
  for (const Action& a : {Action::set_pressure(2000.0), Action::jam(0, 0), Action::set_pressure(500.0),
                          Action::jam(1, 2), Action::set_pressure(3000.0), Action::unjam(0, 0)}) {
    sim.apply(a);
    const Eigen::Vector3d now = sim.state().x.col(node);
    EXPECT_EQ(now.x(), held.x()) << "after " << a.describe();
    EXPECT_EQ(now.y(), held.y()) << "after " << a.describe();
    EXPECT_EQ(now.z(), held.z()) << "after " << a.describe();
  }
  EXPECT_GT(max_height_difference(sim.mesh(), sim.state().x, start), 1e-3) << "the rest of the surface moved";
}

TEST(PaperDevice, OrderOfJamAndPressureMatters) {
  // Paper Fig. 8: jam a level cell then inflate, or inflate then jam.
  Simulator jam_first = levelled_device();
  jam_first.apply(Action::jam(1, 1));
  jam_first.apply(Action::set_pressure(2000.0));
  Simulator pressure_first = levelled_device();
  pressure_first.apply(Action::set_pressure(2000.0));
  pressure_first.apply(Action::jam(1, 1));

  EXPECT_EQ(jam_first.state().pressure_pa, pressure_first.state().pressure_pa);
  EXPECT_EQ(jam_first.state().cell_jammed, pressure_first.state().cell_jammed);
  EXPECT_GT(max_height_difference(jam_first.mesh(), jam_first.state().x, pressure_first.state().x), 1e-3);
  // The cell jammed level stays flatter than the one jammed inflated.
  EXPECT_LT(cell_curvature(jam_first.mesh(), jam_first.state().x, 1, 1),
            cell_curvature(pressure_first.mesh(), pressure_first.state().x, 1, 1));
}

void expect_same_state(const DeviceState& a, const DeviceState& b) {
  EXPECT_EQ(a.pressure_pa, b.pressure_pa);
  EXPECT_EQ(a.cell_jammed, b.cell_jammed);
  EXPECT_EQ(a.node_pinned, b.node_pinned);
  EXPECT_TRUE(a.x == b.x) << "max position change " << (a.x - b.x).cwiseAbs().maxCoeff() << " m";
  EXPECT_TRUE(a.phi_eq == b.phi_eq) << "max phi_eq change " << (a.phi_eq - b.phi_eq).cwiseAbs().maxCoeff();
}

TEST(PaperDevice, RepeatingAnActionChangesNothing) {
  Simulator sim = inflated_device(1500.0);
  for (const Action& a : {Action::set_pressure(1500.0), Action::jam(0, 1), Action::pin(1, 2), Action::unjam(2, 3),
                          Action::unpin(2, 1), Action::set_pressure(2500.0), Action::unjam(0, 1),
                          Action::unpin(1, 2)}) {
    sim.apply(a);
    const DeviceState once = sim.state();
    sim.apply(a);
    SCOPED_TRACE("repeating " + a.describe());
    expect_same_state(once, sim.state());
  }
}

// Five-action sequence of the paper's device, settled both ways.
const std::vector<Action> kMixedSequence = {
    Action::set_pressure(1200.0), Action::jam(0, 1), Action::pin(1, 2),   Action::set_pressure(2000.0),
    Action::unjam(0, 1),          Action::jam(2, 3), Action::unpin(1, 2), Action::set_pressure(1500.0)};

TEST(PaperDevice, StaticAndExplicitSolversAgree) {
  SimulatorOptions static_options, explicit_options;
  static_options.solver = SolverKind::kStatic;
  explicit_options.solver = SolverKind::kExplicit;
  Simulator by_newton(kPaper, SurfaceParameters::paper_defaults(kPaper), static_options);
  const auto start = std::chrono::steady_clock::now();
  Simulator by_euler(kPaper, SurfaceParameters::paper_defaults(kPaper), explicit_options);
  EXPECT_LT(max_height_difference(by_newton.mesh(), by_newton.state().x, by_euler.state().x), 1e-5) << "rest";
  for (const Action& a : kMixedSequence) {
    by_newton.apply(a);
    const SettleReport euler = by_euler.apply(a);
    const double difference = max_height_difference(by_newton.mesh(), by_newton.state().x, by_euler.state().x);
    EXPECT_LT(difference, 1e-5) << "after " << a.describe();
    std::cout << "  " << a.describe() << ": heights differ by " << difference * 1e3 << " mm; explicit "
              << euler.iterations << " steps, " << euler.seconds << " s\n";
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::cout << "  explicit solver total " << seconds << " s\n";
}

}  // namespace
}  // namespace hj
