// Bad user input is refused with a std::invalid_argument whose message names
// what is wrong (docs/style.md, "User input errors are exceptions"), and a
// refused action leaves the device as it was.
#include <gtest/gtest.h>

#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "model/action.h"
#include "model/mesh.h"
#include "model/parameters.h"
#include "sim/effect_registry.h"
#include "sim/simulator.h"

namespace hj {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
const ArrayGeometry kPaper{3, 4, 0.038, 4};

// Expects fn to throw std::invalid_argument whose message holds every word.
void expect_invalid(const std::function<void()>& fn, const std::vector<std::string>& words) {
  try {
    fn();
    ADD_FAILURE() << "no exception; expected one naming \"" << words.front() << "\"";
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    for (const auto& w : words) EXPECT_NE(what.find(w), std::string::npos) << "\"" << w << "\" not in: " << what;
  }
}

ArrayGeometry paper_with(std::function<void(ArrayGeometry&)> change) {
  ArrayGeometry g = kPaper;
  change(g);
  return g;
}

TEST(BadInput, MeshGeometry) {
  expect_invalid([] { (void)Mesh(paper_with([](auto& g) { g.rows = 0; })); }, {"rows", "0"});
  expect_invalid([] { (void)Mesh(paper_with([](auto& g) { g.cols = -1; })); }, {"cols", "-1"});
  expect_invalid([] { (void)Mesh(paper_with([](auto& g) { g.segments = 1; })); }, {"segments"});
  expect_invalid([] { (void)Mesh(paper_with([](auto& g) { g.cell_size_m = 0.0; })); }, {"cell size"});
  expect_invalid([] { (void)Mesh(paper_with([](auto& g) { g.cell_size_m = kNaN; })); }, {"cell size"});
  expect_invalid([] { (void)Mesh(paper_with([](auto& g) { g.cell_size_m = -0.038; })); }, {"cell size"});
  expect_invalid([] { (void)Mesh(paper_with([](auto& g) { g.rows = g.cols = 100000; })); }, {"100000", "points"});
}

SurfaceParameters paper_params_with(std::function<void(SurfaceParameters&)> change) {
  SurfaceParameters p = SurfaceParameters::paper_defaults(kPaper);
  change(p);
  return p;
}

TEST(BadInput, SurfaceParameters) {
  expect_invalid([] { paper_params_with([](auto& p) { p.mass_kg = kNaN; }).validate(); }, {"mass_kg", "kg"});
  expect_invalid([] { paper_params_with([](auto& p) { p.mass_kg = 0.0; }).validate(); }, {"mass_kg"});
  expect_invalid([] { paper_params_with([](auto& p) { p.spring_k = -1.0; }).validate(); }, {"spring_k", "N/m"});
  expect_invalid([] { paper_params_with([](auto& p) { p.kappa_jam = kNaN; }).validate(); }, {"kappa_jam"});
  expect_invalid([] { paper_params_with([](auto& p) { p.max_pressure_pa = 0.0; }).validate(); },
                 {"max_pressure_pa"});
  // The simulator refuses them too, before settling anything.
  expect_invalid([] { (void)Simulator(kPaper, paper_params_with([](auto& p) { p.spring_k = -1.0; })); }, {"spring_k"});
}

TEST(BadInput, ActionOutOfRange) {
  const Mesh mesh(kPaper);
  const SurfaceParameters params = SurfaceParameters::paper_defaults(kPaper);
  expect_invalid([&] { Action::set_pressure(-1.0).validate(mesh, params); }, {"pressure"});
  expect_invalid([&] { Action::set_pressure(kNaN).validate(mesh, params); }, {"pressure"});
  expect_invalid([&] { Action::set_pressure(params.max_pressure_pa + 1.0).validate(mesh, params); },
                 {"pressure", "3.45"});
  expect_invalid([&] { Action::jam(3, 0).validate(mesh, params); }, {"cell", "[3, 0]"});
  expect_invalid([&] { Action::unjam(0, 4).validate(mesh, params); }, {"cell", "[0, 4]"});
  expect_invalid([&] { Action::pin(0, 1).validate(mesh, params); }, {"node", "[0, 1]"});
  expect_invalid([&] { Action::pin(3, 1).validate(mesh, params); }, {"node", "[3, 1]"});
  expect_invalid([&] { Action::unpin(1, 4).validate(mesh, params); }, {"node", "[1, 4]"});
  // The limits themselves are fine.
  EXPECT_NO_THROW(Action::set_pressure(0.0).validate(mesh, params));
  EXPECT_NO_THROW(Action::set_pressure(params.max_pressure_pa).validate(mesh, params));
  EXPECT_NO_THROW(Action::jam(2, 3).validate(mesh, params));
  EXPECT_NO_THROW(Action::pin(2, 3).validate(mesh, params));
}

TEST(BadInput, RefusedActionLeavesTheStateAlone) {
  Simulator sim(kPaper, SurfaceParameters::paper_defaults(kPaper));
  sim.apply(Action::set_pressure(1000.0));
  sim.apply(Action::jam(1, 1));
  const DeviceState before = sim.state();
  for (const Action& bad : {Action::set_pressure(-1.0), Action::set_pressure(kNaN), Action::set_pressure(4000.0),
                            Action::jam(3, 0), Action::unjam(-1, 0), Action::pin(0, 1), Action::pin(3, 1),
                            Action::unpin(1, 0)}) {
    SCOPED_TRACE(bad.describe());
    EXPECT_THROW(sim.apply(bad), std::invalid_argument);
    EXPECT_EQ(sim.state().pressure_pa, before.pressure_pa);
    EXPECT_EQ(sim.state().cell_jammed, before.cell_jammed);
    EXPECT_EQ(sim.state().node_pinned, before.node_pinned);
    EXPECT_TRUE(sim.state().x == before.x);
    EXPECT_TRUE(sim.state().phi_eq == before.phi_eq);
  }
}

TEST(BadInput, UnknownEffectListsTheKnownOnes) {
  expect_invalid([] { EffectRegistry::instance().get("strain-softening"); },
                 {"strain-softening", "springs", "gravity", "pressure", "jamming"});
  SimulatorOptions options;
  options.extra_effects = {"strain-softening"};
  expect_invalid([&] { (void)Simulator(kPaper, SurfaceParameters::paper_defaults(kPaper), options); },
                 {"strain-softening"});
}

TEST(BadInput, EffectParametersAreNamedAndBounded) {
  const EffectInfo& gravity = EffectRegistry::instance().get("gravity");
  EXPECT_EQ(resolve_parameters(gravity, {}).at("mass_kg"), 0.55);
  EXPECT_EQ(resolve_parameters(gravity, {{"mass_kg", 2.0}}).at("mass_kg"), 2.0);
  expect_invalid([&] { (void)resolve_parameters(gravity, {{"weight", 1.0}}); }, {"gravity.weight", "mass_kg"});
  expect_invalid([&] { (void)resolve_parameters(gravity, {{"mass_kg", 1000.0}}); },
                 {"gravity.mass_kg", "1000", "kg", "100"});
  expect_invalid([&] { (void)resolve_parameters(gravity, {{"mass_kg", kNaN}}); }, {"gravity.mass_kg", "nan"});
  expect_invalid([] { (void)make_effects({"gravity"}, {}); }, {"gravity", "twice"});
  expect_invalid([] { (void)make_effects({}, {{"no-such-effect", {}}}); }, {"no-such-effect", "not switched on"});
}

TEST(BadInput, UnknownSolverName) {
  expect_invalid([] { parse_solver_kind("fast"); }, {"fast", "static", "explicit"});
  EXPECT_EQ(parse_solver_kind("static"), SolverKind::kStatic);
  EXPECT_EQ(parse_solver_kind("explicit"), SolverKind::kExplicit);
}

TEST(BadInput, SolverOptions) {
  StaticSolverOptions s;
  s.force_tolerance_n = 0.0;
  expect_invalid([&] { s.validate(); }, {"force_tolerance_n"});
  ExplicitEulerOptions e;
  e.time_step_s = kNaN;
  expect_invalid([&] { e.validate(); }, {"time_step_s"});
}

}  // namespace
}  // namespace hj
