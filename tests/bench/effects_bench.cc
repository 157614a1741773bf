// Cost of one force + stiffness evaluation (what each Newton step of the
// static solver does) with the baseline alone and with every optional
// effect switched on at non-trivial values, on the paper's device at 2 kPa
// with three jammed cells.
// Run: ./build/hj_bench --benchmark_filter=ForceAndStiffness
#include <benchmark/benchmark.h>

#include "sim/simulator.h"
#include "sim/stiffness_matrix.h"

namespace {

using hj::Action;

hj::SimulatorOptions all_effects() {
  hj::SimulatorOptions o;
  o.effect_parameters = {{"bending", {{"kappa_bend", 0.002}}},
                         {"stiffening", {{"beta", 20.0}}},
                         {"jam_contraction", {{"contraction", 0.05}}},
                         {"jam_creep", {{"creep_per_settle", 0.1}}},
                         {"cell_stiffness", {{"grad_x", 0.1}, {"grad_y", -0.1}, {"bulge", 0.1}}},
                         {"area_pressure", {{"weight", 1.0}}},
                         {"boundary_compliance", {{"k_edge", 5000.0}}},
                         {"sensor_tilt", {{"tilt_x_mrad", 2.0}}},
                         {"pressure_offset", {{"gain", 1.02}, {"offset_pa", 10.0}}}};
  for (const auto& [name, values] : o.effect_parameters) o.extra_effects.push_back(name);
  return o;
}

hj::SimulatorOptions bending_only() {
  hj::SimulatorOptions o;
  o.extra_effects = {"bending"};
  o.effect_parameters["bending"] = {{"kappa_bend", 0.002}};
  return o;
}

// args: 0 baseline, 1 all effects, 2 the baseline and bending (the costliest: an
// automatic-differentiation Hessian per bending spring, two at every interior
// and border point).
void BM_ForceAndStiffness(benchmark::State& state) {
  const hj::ArrayGeometry g{3, 4, 0.038, 4};
  hj::Simulator sim(g, hj::SurfaceParameters::paper_defaults(g), state.range(0) == 1   ? all_effects()
                                                                     : state.range(0) == 2 ? bending_only()
                                                                                           : hj::SimulatorOptions{});
  for (const Action& a : {Action::set_pressure(2000.0), Action::jam(0, 0), Action::jam(1, 1), Action::jam(2, 2)})
    sim.apply(a);
  const hj::ForceModel& model = sim.model();
  const hj::DeviceState& s = sim.state();
  hj::StiffnessMatrix k(sim.mesh(), model.fixed_points(s), [&](hj::StiffnessSink& sink) { model.add_stiffness(s, s.x, sink); });
  Eigen::Matrix3Xd f;
  for (auto _ : state) {
    model.forces(s, s.x, f);
    k.set_zero();
    model.add_stiffness(s, s.x, k);
    benchmark::DoNotOptimize(f.data());
    benchmark::DoNotOptimize(k.matrix().valuePtr());
  }
  state.counters["nonzeros"] = static_cast<double>(k.matrix().nonZeros());
}

BENCHMARK(BM_ForceAndStiffness)->Arg(0)->Arg(1)->Arg(2)->Unit(benchmark::kMicrosecond);

}  // namespace
