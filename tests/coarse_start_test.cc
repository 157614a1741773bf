// The coarse-mesh start of a large free net's levelling crossing
// (src/sim/coarse_start.h): resampling between meshes keeps what a bilinear
// grid can hold, and the fine settle from the coarse dome ends on the dome
// the paper's explicit Euler reaches, in fewer fine steps than from the
// mirrored sag.
#include <gtest/gtest.h>

#include <stdexcept>
#include <utility>

#include "model/action.h"
#include "sim/coarse_start.h"
#include "sim/effect_registry.h"
#include "sim/simulator.h"
#include "sim/surface_measures.h"

namespace hj {
namespace {

// A smooth displacement bilinear in the rest coordinates (u v terms
// included): the fields a bilinear resampling must reproduce exactly.
Eigen::Matrix3Xd bilinear_field(const Mesh& mesh) {
  Eigen::Matrix3Xd x(3, mesh.num_points());
  for (int i = 0; i < mesh.point_rows(); ++i)
    for (int j = 0; j < mesh.point_cols(); ++j) {
      const double u = j * mesh.spacing(), v = i * mesh.spacing();
      x.col(mesh.index(i, j)) << 1.1 * u + 0.01 * v, 0.9 * v - 0.02 * u, 0.3 * u - 0.2 * v + 5.0 * u * v;
    }
  return x;
}

TEST(ResampleToMesh, KeepsABilinearFieldAndTheSharedPointsExactly) {
  const Mesh fine(ArrayGeometry{3, 4, 0.038, 4}), coarse(ArrayGeometry{3, 4, 0.038, 2});
  const Eigen::Matrix3Xd x = bilinear_field(fine);
  const Eigen::Matrix3Xd down = resample_to_mesh(fine, x, coarse);
  EXPECT_LT((down - bilinear_field(coarse)).cwiseAbs().maxCoeff(), 1e-15);
  for (int i = 0; i < coarse.point_rows(); ++i)
    for (int j = 0; j < coarse.point_cols(); ++j)
      EXPECT_EQ(down.col(coarse.index(i, j)), x.col(fine.index(2 * i, 2 * j))) << "a point both meshes have";
  EXPECT_LT((resample_to_mesh(coarse, down, fine) - x).cwiseAbs().maxCoeff(), 1e-15);
}

TEST(ResampleToMesh, RefusesMeshesOfAnotherArrayOrPositionsOfAnotherMesh) {
  const Mesh a(ArrayGeometry{3, 4, 0.038, 4}), b(ArrayGeometry{3, 5, 0.038, 2});
  EXPECT_THROW(resample_to_mesh(a, Eigen::Matrix3Xd::Zero(3, a.num_points()), b), std::invalid_argument);
  EXPECT_THROW(resample_to_mesh(a, Eigen::Matrix3Xd::Zero(3, 7), Mesh(ArrayGeometry{3, 4, 0.038, 2})),
               std::invalid_argument);
}

TEST(CoarseSegments, HalvesDownToTwo) {
  EXPECT_EQ(coarse_segments(4), 2);
  EXPECT_EQ(coarse_segments(10), 5);
  EXPECT_EQ(coarse_segments(3), 0);
  EXPECT_EQ(coarse_segments(2), 0);
}

const ArrayGeometry kLarge{9, 12, 0.038, 4};

TEST(CoarseMeshStart, OnlyForAFreeNetCrossingLevelling) {
  Simulator sim(kLarge, SurfaceParameters::paper_defaults(kLarge));
  ArrayGeometry g = kLarge;
  g.segments = 2;
  const ForceModel coarse(Mesh(g), sim.params(), make_effects({}, {}));
  const double levelling = sim.params().levelling_pressure_pa(sim.mesh());
  EXPECT_FALSE(coarse_mesh_start(sim.model(), coarse, sim.state(), 0.9 * levelling, {}).has_value());
  DeviceState jammed = sim.state();
  jammed.cell_jammed[sim.mesh().cell_index(4, 6)] = 1;
  EXPECT_FALSE(coarse_mesh_start(sim.model(), coarse, jammed, 2000.0, {}).has_value()) << "a jammed cell";
  const auto start = coarse_mesh_start(sim.model(), coarse, sim.state(), 2000.0, {});
  ASSERT_TRUE(start.has_value());
  EXPECT_EQ(start->x.cols(), sim.mesh().num_points());
  EXPECT_GT(point_heights(sim.mesh(), start->x).maxCoeff(), 0.1) << "m: the coarse dome, up";
}

TEST(CoarseMeshStart, ReachesTheExplicitEulerDomeInFewerFineSteps) {
  // 9 x 12, rest to 2 kPa. The paper's explicit Euler ends with the centre
  // at 166.953059 mm (365,627 steps, 53 s; measured 2026-11-25), and the
  // settle from the coarse dome on the same surface (7.9e-6 mm at most
  // apart). The mirrored sag leads to a neighbouring symmetric equilibrium
  // instead (centre 167.033 mm, 2.0 mm apart near the edges), in 24 fine
  // steps to the coarse start's 9.
  auto rise = [](bool coarse) {
    SimulatorOptions options;
    options.coarse_start = coarse;
    Simulator sim(kLarge, SurfaceParameters::paper_defaults(kLarge), options);
    const SettleReport report = sim.apply(Action::set_pressure(2000.0));
    EXPECT_TRUE(report.converged);
    EXPECT_LT(report.residual_n, 1e-9);
    return std::make_pair(report, point_heights(sim.mesh(), sim.state().x));
  };
  const auto [from_coarse, z_coarse] = rise(true);
  EXPECT_NEAR(z_coarse(18, 24), 0.166953059, 1e-8) << "m, the centre";
  EXPECT_NEAR((z_coarse - z_coarse.rowwise().reverse()).cwiseAbs().maxCoeff(), 0.0, 1e-12) << "m, left-right";
  EXPECT_NEAR((z_coarse - z_coarse.colwise().reverse()).cwiseAbs().maxCoeff(), 0.0, 1e-12) << "m, up-down";
  const auto [from_mirror, z_mirror] = rise(false);
  EXPECT_LT(from_coarse.iterations, from_mirror.iterations);
}

}  // namespace
}  // namespace hj
