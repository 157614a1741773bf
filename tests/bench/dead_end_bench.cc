// A planner's dead end: the 9 x 12 Algorithm 2 plan of the Stanford bunny
// jams 25 cells in the sag and rises to 200 Pa; at 250 Pa the flow folds the
// sag past 120 degrees and wanders in place. The time to the refusal, with
// the dead-end watch's stall limit (arg 0, planners' default) and without it
// (arg 1: only the flat-fold refusal and the step budget end it).
// Run: ./build/hj_bench --benchmark_filter=BM_PlannerDeadEnd
#include <benchmark/benchmark.h>

#include "../planner_dead_ends.h"
#include "plan/planner.h"
#include "sim/simulator.h"

namespace {

using hj::Action;

void BM_PlannerDeadEnd(benchmark::State& state) {
  const hj::ArrayGeometry g{9, 12, 0.038, 4};
  hj::PlanRequest request{g, hj::SurfaceParameters::paper_defaults(g), {}, {}, {}};
  hj::SimulatorOptions options = hj::simulator_options(request, {});
  if (state.range(0) == 1) options.refuse_stall_steps = 0;
  const std::vector<Action> steps = hj::testing::bunny_9x12_jammed_sag();
  for (auto _ : state) {
    state.PauseTiming();
    hj::Simulator sim(g, request.params, options);
    for (const Action& a : steps) sim.apply(a);
    state.ResumeTiming();
    try {
      sim.apply(Action::set_pressure(250.0));
      state.SkipWithError("250 Pa settled: no dead end to time");
    } catch (const hj::NoEquilibrium&) {
    }
  }
}
BENCHMARK(BM_PlannerDeadEnd)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->Iterations(1);

}  // namespace
