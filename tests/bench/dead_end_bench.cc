// A planner's dead end: the 9 x 12 Algorithm 2 plan of the Stanford bunny
// jams 25 cells in the sag and rises to 200 Pa; at 250 Pa the flow folds the
// sag past 120 degrees and wanders in place. The time to the refusal, with
// the dead-end watch's stall limit (arg 0, planners' default) and without it
// (arg 1: only the flat-fold refusal and the step budget end it).
// BM_PlannerDeadEndCycle: the same on the 9 x 12 Luxembourg plan's jammed
// sag at 250 Pa, whose flow swings in a cycle of about 40 steps.
// Run: ./build/hj_bench --benchmark_filter=BM_PlannerDeadEnd
#include <benchmark/benchmark.h>

#include "../planner_dead_ends.h"
#include "plan/planner.h"
#include "sim/simulator.h"

namespace {

using hj::Action;

void time_refusal(benchmark::State& state, const std::vector<Action>& steps, double pressure_pa) {
  const hj::ArrayGeometry g{9, 12, 0.038, 4};
  hj::PlanRequest request{g, hj::SurfaceParameters::paper_defaults(g), {}, {}, {}};
  hj::SimulatorOptions options = hj::simulator_options(request, {});
  if (state.range(0) == 1) options.refuse_stall_steps = 0;
  for (auto _ : state) {
    state.PauseTiming();
    hj::Simulator sim(g, request.params, options);
    for (const Action& a : steps) sim.apply(a);
    state.ResumeTiming();
    try {
      sim.apply(Action::set_pressure(pressure_pa));
      state.SkipWithError("the pressure settled: no dead end to time");
    } catch (const hj::NoEquilibrium&) {
    }
  }
}

void BM_PlannerDeadEnd(benchmark::State& state) { time_refusal(state, hj::testing::bunny_9x12_jammed_sag(), 250.0); }

void BM_PlannerDeadEndCycle(benchmark::State& state) {
  time_refusal(state, hj::testing::luxembourg_9x12_cycling_sag(), 250.0);
}
BENCHMARK(BM_PlannerDeadEnd)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK(BM_PlannerDeadEndCycle)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->Iterations(1);

}  // namespace
