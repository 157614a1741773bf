// The snap-through settle (sim/implicit_flow.h) against the paper's explicit
// Euler, each polished by the static solver, on the case of
// tests/snap_through_test.cc: a 4 x 6 array jammed in its rest sag, then
// 1 kPa (the static solver alone finds no equilibrium). And a jam on a
// 9 x 12 array with and without the jam/pin settle skip.
// Run: ./build/hj_bench --benchmark_filter='Snap|JamAtEquilibrium'
#include <benchmark/benchmark.h>

#include "sim/explicit_euler.h"
#include "sim/implicit_flow.h"
#include "sim/simulator.h"

namespace {

const hj::ArrayGeometry kSnapArray{4, 6, 0.038, 4};

hj::Simulator jammed_sag() {
  hj::Simulator sim(kSnapArray, hj::SurfaceParameters::paper_defaults(kSnapArray));
  for (int r = 0; r < kSnapArray.rows; ++r)
    for (int c = 0; c < kSnapArray.cols; ++c) sim.apply(hj::Action::jam(r, c));
  return sim;
}

// arg 0: implicit flow, 1: explicit Euler; both then polished.
void BM_SnapThroughSettle(benchmark::State& state) {
  const hj::Simulator sim = jammed_sag();
  long iterations = 0;
  for (auto _ : state) {
    hj::DeviceState s = sim.state();
    s.pressure_pa = 1000.0;
    const hj::SettleReport first = state.range(0) == 0 ? hj::settle_implicit_flow(sim.model(), s)
                                                       : hj::settle_explicit(sim.model(), s);
    const hj::SettleReport polish = hj::settle_static(sim.model(), s);
    if (!first.converged || !polish.converged) state.SkipWithError("no equilibrium");
    iterations += first.iterations + polish.iterations;
  }
  state.counters["iterations"] = benchmark::Counter(double(iterations), benchmark::Counter::kAvgIterations);
}
BENCHMARK(BM_SnapThroughSettle)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

// Jams on a 9 x 12 array at 200 Pa, one more cell each iteration (each at
// equilibrium); arg: 1 skip on (the default), 0 off.
void BM_JamAtEquilibrium(benchmark::State& state) {
  const hj::ArrayGeometry g{9, 12, 0.038, 4};
  hj::SimulatorOptions options;
  options.skip_settle_after_jam_or_pin = state.range(0) != 0;
  hj::Simulator sim(g, hj::SurfaceParameters::paper_defaults(g), options);
  sim.apply(hj::Action::set_pressure(200.0));
  int cell = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(sim.apply(hj::Action::jam(cell / g.cols, cell % g.cols)).iterations);
    cell = (cell + 1) % (g.rows * g.cols);
  }
}
BENCHMARK(BM_JamAtEquilibrium)->Arg(1)->Arg(0)->Unit(benchmark::kMillisecond)->Iterations(40);

}  // namespace
