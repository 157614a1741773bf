// The optional effects (src/sim/effects) on the simulated device: at their
// no-op values they change nothing, and each one, switched on, shows the
// physical fact it stands for; the static and explicit solvers agree with
// effects on.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <iostream>
#include <map>
#include <string>

#include "calib/replay.h"
#include "calib/session.h"
#include "model/action.h"
#include "scratch_dir.h"
#include "sim/simulator.h"

namespace hj {
namespace {

const ArrayGeometry kPaper{3, 4, 0.038, 4};

SimulatorOptions with(const std::map<std::string, EffectParameterValues>& effects) {
  SimulatorOptions o;
  for (const auto& [name, values] : effects) {
    o.extra_effects.push_back(name);
    o.effect_parameters[name] = values;
  }
  return o;
}

Simulator device(const SimulatorOptions& options, const std::vector<Action>& actions,
                 const ArrayGeometry& g = kPaper) {
  Simulator sim(g, SurfaceParameters::paper_defaults(g), options);
  for (const Action& a : actions) sim.apply(a);
  return sim;
}

// Height (m) of the middle point of cell (r, c).
double centre_z(const Simulator& sim, int r, int c) {
  const int p = sim.mesh().segments();
  return sim.state().x(2, sim.mesh().index(r * p + p / 2, c * p + p / 2));
}

double max_difference(const Eigen::Matrix3Xd& a, const Eigen::Matrix3Xd& b) { return (a - b).cwiseAbs().maxCoeff(); }

const std::vector<Action> kSequence = {Action::set_pressure(1500.0), Action::jam(1, 1), Action::pin(1, 2),
                                       Action::set_pressure(600.0)};

// --- No-op values ------------------------------------------------------------

struct NoOp {
  std::string effect;
  EffectParameterValues values;
};

void PrintTo(const NoOp& c, std::ostream* os) { *os << c.effect; }

class EffectAtNoOpValues : public testing::TestWithParam<NoOp> {};

TEST_P(EffectAtNoOpValues, ChangesNothing) {
  static const Simulator baseline = device({}, kSequence);
  const Simulator sim = device(with({{GetParam().effect, GetParam().values}}), kSequence);
  EXPECT_LT(max_difference(sim.state().x, baseline.state().x), 1e-9) << "m";
  EXPECT_EQ(sim.state().phi_eq, baseline.state().phi_eq);
}

INSTANTIATE_TEST_SUITE_P(Effects, EffectAtNoOpValues,
                         testing::Values(NoOp{"bending", {{"kappa_bend", 0.0}}}, NoOp{"stiffening", {{"beta", 0.0}}},
                                         NoOp{"jam_contraction", {{"contraction", 0.0}}},
                                         NoOp{"jam_creep", {{"creep_per_settle", 0.0}}},
                                         NoOp{"cell_stiffness", {{"grad_x", 0.0}, {"grad_y", 0.0}, {"bulge", 0.0}}},
                                         NoOp{"cell_defect", {{"factor", 1.0}, {"row", 1}, {"col", 1}}},
                                         NoOp{"area_pressure", {{"weight", 0.0}}},
                                         NoOp{"pressure_offset", {{"gain", 1.0}, {"offset_pa", 0.0}}},
                                         NoOp{"sensor_tilt", {}}),
                         [](const testing::TestParamInfo<NoOp>& info) { return info.param.effect; });

// --- One physical fact each ----------------------------------------------------

TEST(Bending, ReducesTheSagAndTheBulge) {
  const std::vector<Action> bulge = {Action::set_pressure(2000.0)};
  const auto bending = with({{"bending", {{"kappa_bend", 0.05}}}});
  const double sag0 = centre_z(device({}, {}), 1, 1), sag1 = centre_z(device(bending, {}), 1, 1);
  const double bulge0 = centre_z(device({}, bulge), 1, 1), bulge1 = centre_z(device(bending, bulge), 1, 1);
  EXPECT_LT(sag0, 0.0);
  EXPECT_GT(sag1, sag0) << "a stiffer membrane sags less";
  EXPECT_LT(sag1, 0.0);
  EXPECT_GT(bulge0, 0.0);
  EXPECT_LT(bulge1, bulge0) << "and bulges less";
  EXPECT_GT(bulge1, 0.0);
}

TEST(Stiffening, ReducesTheBulge) {
  const std::vector<Action> bulge = {Action::set_pressure(2000.0)};
  const double z0 = centre_z(device({}, bulge), 1, 1);
  const double z1 = centre_z(device(with({{"stiffening", {{"beta", 100.0}}}}), bulge), 1, 1);
  EXPECT_LT(z1, 0.97 * z0);
  EXPECT_GT(z1, 0.0);
}

TEST(JamContraction, LowersAJammedBulge) {
  const std::vector<Action> jammed = {Action::set_pressure(2000.0), Action::jam(1, 1)};
  const double z0 = centre_z(device({}, jammed), 1, 1);
  const Simulator contracted = device(with({{"jam_contraction", {{"contraction", 0.1}}}}), jammed);
  EXPECT_LT(centre_z(contracted, 1, 1), z0 - 1e-4) << "m";
  // An unjammed cell does not contract: the effect does nothing before the jam.
  const std::vector<Action> unjammed = {Action::set_pressure(2000.0)};
  EXPECT_LT(max_difference(device(with({{"jam_contraction", {{"contraction", 0.1}}}}), unjammed).state().x,
                           device({}, unjammed).state().x),
            1e-9);
}

// Height (m) of the middle of cell (r, c) above the mean of its four corners.
double dome(const Simulator& sim, int r, int c) {
  const Mesh& m = sim.mesh();
  const int p = m.segments();
  double corners = 0.0;
  for (int di : {0, p})
    for (int dj : {0, p}) corners += sim.state().x(2, m.index(r * p + di, c * p + dj));
  return centre_z(sim, r, c) - 0.25 * corners;
}

TEST(JamCreep, AHeldDomeYieldsSettleBySettle) {
  // Jammed as a dome at 2 kPa, then the pressure is removed: a perfect jam
  // holds its dome; a creeping one lets more of it go with every settle
  // (a pin elsewhere only triggers one more settle).
  // A soft jam (kappa_jam 0.05 N m/rad), so that it visibly bends under the load.
  SurfaceParameters params = SurfaceParameters::paper_defaults(kPaper);
  params.kappa_jam = 0.05;
  const std::vector<Action> held = {Action::set_pressure(2000.0), Action::jam(1, 1), Action::set_pressure(0.0)};
  Simulator perfect(kPaper, params), creeping(kPaper, params, with({{"jam_creep", {{"creep_per_settle", 0.5}}}}));
  for (const Action& a : held) {
    perfect.apply(a);
    creeping.apply(a);
  }
  const double after1 = dome(creeping, 1, 1);
  creeping.apply(Action::pin(2, 3));
  const double after2 = dome(creeping, 1, 1);
  std::cout << "  dome of the jammed cell at 0 kPa: perfect " << dome(perfect, 1, 1) * 1e3 << " mm, creeping "
            << after1 * 1e3 << " mm, after one more settle " << after2 * 1e3 << " mm\n";
  EXPECT_GT(dome(perfect, 1, 1), 1e-3) << "the perfect jam holds a dome";
  EXPECT_LT(after1, dome(perfect, 1, 1) - 1e-4);
  EXPECT_LT(after2, after1 - 1e-5);
}

TEST(CellStiffness, AStifferSideBulgesLess) {
  const std::vector<Action> bulge = {Action::set_pressure(2000.0)};
  const Simulator even = device({}, bulge);
  EXPECT_NEAR(centre_z(even, 1, 0), centre_z(even, 1, 3), 1e-9) << "the baseline is symmetric";
  const Simulator graded = device(with({{"cell_stiffness", {{"grad_x", 0.3}}}}), bulge);
  EXPECT_LT(centre_z(graded, 1, 3), centre_z(graded, 1, 0) - 1e-4) << "+x is stiffer";
  const Simulator bulged = device(with({{"cell_stiffness", {{"bulge", -0.3}}}}), bulge);
  EXPECT_GT(centre_z(bulged, 1, 1), centre_z(even, 1, 1) + 1e-4) << "a softer middle bulges more";
}

TEST(CellDefect, ASoftCellBulgesMoreThanItsMirrorImage) {
  const std::vector<Action> bulge = {Action::set_pressure(2000.0)};
  const Simulator even = device({}, bulge);
  const Simulator soft = device(with({{"cell_defect", {{"factor", 0.4}, {"row", 1}, {"col", 2}}}}), bulge);
  EXPECT_GT(centre_z(soft, 1, 2), centre_z(even, 1, 2) + 1e-3) << "the soft cell bulges more";
  EXPECT_GT(centre_z(soft, 1, 2), centre_z(soft, 1, 1) + 1e-3) << "than its mirror image";
  const Simulator stiff = device(with({{"cell_defect", {{"factor", 3.0}, {"row", 1}, {"col", 2}}}}), bulge);
  EXPECT_LT(centre_z(stiff, 1, 2), centre_z(even, 1, 2) - 1e-3) << "a stiff cell bulges less";
  // A cell outside the array is no cell of it.
  const Simulator nowhere = device(with({{"cell_defect", {{"factor", 0.4}, {"row", 40}, {"col", 40}}}}), bulge);
  EXPECT_LT(max_difference(nowhere.state().x, even.state().x), 1e-9);
}

TEST(AreaPressure, AStretchedSurfaceCarriesMoreLoad) {
  // At 0.8 kPa: above about 1.1 kPa the stretched-area load on this net
  // (no shear stiffness, linear springs) has no equilibrium left.
  const std::vector<Action> bulge = {Action::set_pressure(800.0)};
  const double z0 = centre_z(device({}, bulge), 1, 1);
  const double z1 = centre_z(device(with({{"area_pressure", {{"weight", 1.0}}}}), bulge), 1, 1);
  EXPECT_GT(z1, z0 + 1e-4);
}

TEST(BoundaryCompliance, TheEdgeGivesByItsReactionOverKEdge) {
  // The clamp's reaction at the edge points of the baseline (the force the
  // clamp holds) divided by k_edge is how far a compliant edge gives, to
  // first order; a very stiff edge is the clamp.
  const std::vector<Action> bulge = {Action::set_pressure(2000.0)};
  const Simulator clamped = device({}, bulge);
  Eigen::Matrix3Xd reaction;
  clamped.model().forces(clamped.state(), clamped.state().x, reaction);
  const Simulator stiff = device(with({{"boundary_compliance", {{"k_edge", 1e6}}}}), bulge);
  EXPECT_LT(max_difference(stiff.state().x, clamped.state().x), 1e-5) << "m";
  const double k_edge = 2e4;
  const Simulator soft = device(with({{"boundary_compliance", {{"k_edge", k_edge}}}}), bulge);
  const Mesh& mesh = soft.mesh();
  double worst = 0.0, largest = 0.0;
  for (int p = 0; p < mesh.num_points(); ++p) {
    if (!mesh.is_boundary(p)) continue;
    const Eigen::Vector3d moved = soft.state().x.col(p) - clamped.state().x.col(p);
    const Eigen::Vector3d expected = reaction.col(p) / k_edge;
    worst = std::max(worst, (moved - expected).norm());
    largest = std::max(largest, expected.norm());
  }
  EXPECT_GT(largest, 1e-6) << "m: the edge gives measurably";
  EXPECT_LT(worst, 0.2 * largest) << "m";
}

TEST(PressureOffset, GainAndOffsetAreAPressureChange) {
  const Simulator shifted =
      device(with({{"pressure_offset", {{"gain", 1.2}, {"offset_pa", 100.0}}}}), {Action::set_pressure(1000.0)});
  const Simulator same = device({}, {Action::set_pressure(1.2 * 1000.0 + 100.0)});
  EXPECT_LT(max_difference(shifted.state().x, same.state().x), 1e-8) << "m";
}

TEST(SensorTilt, AddsExactlyThePlaneToThePredictedFrames) {
  testing_support::ScratchDir dir("tilt");
  std::ofstream(dir.path / "session.json") << R"({
    "format": "hapticjam.session/1", "name": "tilt",
    "device": {"rows": 1, "cols": 2, "cell_size_mm": 38.0, "max_pressure_kpa": 3.45},
    "grid": {"nx": 20, "ny": 10, "x0_mm": 0.0, "y0_mm": 0.0, "dx_mm": 4.0, "dy_mm": 4.0},
    "steps": [{"op": "set_pressure", "kpa": 1.0}, {"op": "capture", "frame": "frames/000.csv"}]})";
  const Session session = read_session(dir.path);
  const SurfaceParameters params = SurfaceParameters::paper_defaults(session.device.geometry());
  const auto plain = replay_session(session, 4, params, {});
  const auto tilted = replay_session(
      session, 4, params, with({{"sensor_tilt", {{"tilt_x_mrad", 10.0}, {"tilt_y_mrad", -4.0}, {"offset_mm", 1.5}}}}));
  ASSERT_EQ(plain.size(), 1u);
  int compared = 0;
  for (int iy = 0; iy < session.grid.ny; ++iy)
    for (int ix = 0; ix < session.grid.nx; ++ix) {
      const double a = plain[0].heights_mm(iy, ix), b = tilted[0].heights_mm(iy, ix);
      ASSERT_EQ(std::isnan(a), std::isnan(b));
      if (std::isnan(a)) continue;
      // About the centre (38, 19) mm of the 1 x 2 array.
      const double plane = 1.5 + 1e-3 * (10.0 * (session.grid.x_mm(ix) - 38.0) - 4.0 * (session.grid.y_mm(iy) - 19.0));
      EXPECT_NEAR(b - a, plane, 1e-9) << "sample " << ix << ", " << iy;
      ++compared;
    }
  EXPECT_GT(compared, 150);
}

// --- Solvers -------------------------------------------------------------------

TEST(EffectsOn, StaticAndExplicitSolversAgree) {
  const ArrayGeometry small{1, 2, 0.038, 4};
  SimulatorOptions options = with({{"bending", {{"kappa_bend", 0.01}}},
                                   {"stiffening", {{"beta", 50.0}}},
                                   {"jam_contraction", {{"contraction", 0.05}}},
                                   {"cell_stiffness", {{"grad_x", 0.2}, {"bulge", 0.1}}},
                                   {"area_pressure", {}},
                                   {"boundary_compliance", {{"k_edge", 2000.0}}},
                                   {"pressure_offset", {{"gain", 1.1}, {"offset_pa", 30.0}}}});
  SimulatorOptions explicit_options = options;
  explicit_options.solver = SolverKind::kExplicit;
  Simulator by_newton(small, SurfaceParameters::paper_defaults(small), options);
  Simulator by_euler(small, SurfaceParameters::paper_defaults(small), explicit_options);
  EXPECT_LT(max_difference(by_newton.state().x, by_euler.state().x), 1e-5) << "rest";
  for (const Action& a : {Action::set_pressure(1500.0), Action::jam(0, 1), Action::set_pressure(800.0)}) {
    by_newton.apply(a);
    by_euler.apply(a);
    EXPECT_LT(max_difference(by_newton.state().x, by_euler.state().x), 1e-5) << "after " << a.describe();
  }
}

}  // namespace
}  // namespace hj
