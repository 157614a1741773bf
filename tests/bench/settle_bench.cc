// Settling speed: from rest to 2 kPa, one action after that (jam a cell,
// then 1 kPa), and a jam-and-pin session, for the static solver and the
// paper's explicit Euler; BM_SettleJamPinSessionSpeedup runs both on the
// session and reports their ratio.
// Run: ./build/hj_bench --benchmark_filter=Settle
#include <benchmark/benchmark.h>

#include <chrono>
#include <ctime>
#include <exception>
#include <functional>

#include "sim/simulator.h"

namespace {

using hj::Action;
using hj::ArrayGeometry;
using hj::SimulatorOptions;
using hj::SolverKind;

// Times one action on a simulator that `prepare` brought to its start
// state (untimed). args: rows, cols, segments, solver (0 static, 1 explicit).
void time_one_action(benchmark::State& state, const std::function<void(hj::Simulator&)>& prepare,
                     const Action& action) {
  const ArrayGeometry g{static_cast<int>(state.range(0)), static_cast<int>(state.range(1)), 0.038,
                        static_cast<int>(state.range(2))};
  SimulatorOptions options;
  options.solver = state.range(3) == 0 ? SolverKind::kStatic : SolverKind::kExplicit;
  long iterations = 0;
  for (auto _ : state) {
    state.PauseTiming();
    hj::Simulator sim(g, hj::SurfaceParameters::paper_defaults(g), options);
    prepare(sim);
    state.ResumeTiming();
    try {
      iterations += sim.apply(action).iterations;
    } catch (const std::exception& e) {
      // A hard case the solver gives up on is a result, not a crash.
      state.SkipWithError(e.what());
      break;
    }
  }
  state.counters["solver_iterations"] =
      benchmark::Counter(static_cast<double>(iterations), benchmark::Counter::kAvgIterations);
}

void BM_SettleRestTo2kPa(benchmark::State& state) {
  time_one_action(state, [](hj::Simulator&) {}, Action::set_pressure(2000.0));
}

void BM_SettleOneActionAfter2kPa(benchmark::State& state) {
  time_one_action(
      state,
      [](hj::Simulator& sim) {
        sim.apply(Action::set_pressure(2000.0));
        sim.apply(Action::jam(1, 1));
      },
      Action::set_pressure(1000.0));
}

// A planner-sized step: jam the centre cell at 2 kPa, then 1.9 kPa.
void BM_SettleCentreJamThenStep(benchmark::State& state) {
  const int rows = static_cast<int>(state.range(0)), cols = static_cast<int>(state.range(1));
  time_one_action(
      state,
      [&](hj::Simulator& sim) {
        sim.apply(Action::set_pressure(2000.0));
        sim.apply(Action::jam(rows / 2, cols / 2));
      },
      Action::set_pressure(1900.0));
}

// A planner's session end to end, as one timed run from a fresh simulator:
// rest, 2 kPa, jam the centre cell, pin a node of it, 2.5 kPa. (With a
// corner cell jammed and pinned instead, 9 x 12 has no equilibrium at 2.5 kPa.)
ArrayGeometry session_geometry(const benchmark::State& state) {
  return {static_cast<int>(state.range(0)), static_cast<int>(state.range(1)), 0.038, static_cast<int>(state.range(2))};
}

// The session from a fresh simulator; returns the solver iterations of all its settles.
long run_jam_pin_session(const ArrayGeometry& g, SolverKind solver) {
  SimulatorOptions options;
  options.solver = solver;
  const Action session[] = {Action::set_pressure(2000.0), Action::jam(g.rows / 2, g.cols / 2),
                            Action::pin(g.rows / 2, g.cols / 2), Action::set_pressure(2500.0)};
  hj::Simulator sim(g, hj::SurfaceParameters::paper_defaults(g), options);
  long iterations = sim.last_settle().iterations;
  for (const Action& a : session) iterations += sim.apply(a).iterations;
  return iterations;
}

void BM_SettleJamPinSession(benchmark::State& state) {
  const ArrayGeometry g = session_geometry(state);
  const SolverKind solver = state.range(3) == 0 ? SolverKind::kStatic : SolverKind::kExplicit;
  long iterations = 0;
  for (auto _ : state) {
    try {
      iterations += run_jam_pin_session(g, solver);
    } catch (const std::exception& e) {
      state.SkipWithError(e.what());
      break;
    }
  }
  state.counters["solver_iterations"] =
      benchmark::Counter(static_cast<double>(iterations), benchmark::Counter::kAvgIterations);
}

// The free membrane through levelling, where the sag snaps to a dome: a
// 6 x 8 array from rest to 300 Pa (a sag) and then 350 Pa (a dome), the
// pressures a plan steps through there. The finer meshes are the device
// emulator's; counters give each settle's solver steps.
void BM_SettleThroughLevelling(benchmark::State& state) {
  const ArrayGeometry g = session_geometry(state);
  long to_sag = 0, to_dome = 0;
  for (auto _ : state) {
    try {
      hj::Simulator sim(g, hj::SurfaceParameters::paper_defaults(g));
      to_sag += sim.apply(Action::set_pressure(300.0)).iterations;
      to_dome += sim.apply(Action::set_pressure(350.0)).iterations;
    } catch (const std::exception& e) {
      state.SkipWithError(e.what());
      break;
    }
  }
  const auto average = [](double total) { return benchmark::Counter(total, benchmark::Counter::kAvgIterations); };
  state.counters["to_300pa_steps"] = average(double(to_sag));
  state.counters["to_350pa_steps"] = average(double(to_dome));
}

// Seconds of CPU this process has used: on a shared machine the fairer
// clock for a ratio of two long runs.
double process_cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

// The same session by both solvers in one run, each timed end to end:
// static_s, explicit_s (wall) and speedup = explicit_s / static_s, and the
// same on CPU time (static_cpu_s, explicit_cpu_s, speedup_cpu). The
// benchmark's own time is the sum.
void BM_SettleJamPinSessionSpeedup(benchmark::State& state) {
  using Clock = std::chrono::steady_clock;
  const ArrayGeometry g = session_geometry(state);
  double wall[2] = {0.0, 0.0}, cpu[2] = {0.0, 0.0};
  long iterations[2] = {0, 0};
  for (auto _ : state) {
    for (int i = 0; i < 2; ++i) {
      const auto start = Clock::now();
      const double cpu_start = process_cpu_seconds();
      try {
        iterations[i] += run_jam_pin_session(g, i == 0 ? SolverKind::kStatic : SolverKind::kExplicit);
      } catch (const std::exception& e) {
        state.SkipWithError(e.what());
        return;
      }
      wall[i] += std::chrono::duration<double>(Clock::now() - start).count();
      cpu[i] += process_cpu_seconds() - cpu_start;
    }
  }
  const auto average = [](double total) { return benchmark::Counter(total, benchmark::Counter::kAvgIterations); };
  state.counters["static_s"] = average(wall[0]);
  state.counters["explicit_s"] = average(wall[1]);
  state.counters["static_cpu_s"] = average(cpu[0]);
  state.counters["explicit_cpu_s"] = average(cpu[1]);
  state.counters["static_iterations"] = average(static_cast<double>(iterations[0]));
  state.counters["explicit_iterations"] = average(static_cast<double>(iterations[1]));
  state.counters["speedup"] = wall[1] / wall[0];
  state.counters["speedup_cpu"] = cpu[1] / cpu[0];
}

BENCHMARK(BM_SettleRestTo2kPa)->Args({3, 4, 4, 0})->Args({3, 4, 4, 1})->Args({9, 12, 4, 0})->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_SettleOneActionAfter2kPa)->Args({3, 4, 4, 0})->Args({3, 4, 4, 1})->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_SettleCentreJamThenStep)->Args({3, 4, 4, 0})->Args({3, 4, 4, 1})->Args({9, 12, 4, 0})->Unit(benchmark::kMillisecond)->Iterations(3);
// The slow ones, run by name: 9 x 12 explicit, p = 10 (both solvers;
// explicit Euler there takes over an hour), and the 9 x 12
// jammed step (2 -> 1 kPa; a corner cell jammed keeps no mirror, so it
// settles on every DOF).
BENCHMARK(BM_SettleJamPinSession)->Args({3, 4, 4, 0})->Args({9, 12, 4, 0})->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK(BM_SettleJamPinSession)->Name("Slow/BM_SettleJamPinSession")->Args({3, 4, 4, 1})->Args({9, 12, 4, 1})->Unit(benchmark::kMillisecond)->Iterations(1);
// Both solvers on the session in one run (args: rows, cols, segments); the
// 9 x 12 one, slow, spends nearly all its time in explicit Euler.
BENCHMARK(BM_SettleThroughLevelling)->Args({6, 8, 4})->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK(BM_SettleThroughLevelling)->Name("Slow/BM_SettleThroughLevelling")->Args({6, 8, 6})->Args({6, 8, 8})->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK(BM_SettleJamPinSessionSpeedup)->Args({3, 4, 4})->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK(BM_SettleJamPinSessionSpeedup)->Name("Slow/BM_SettleJamPinSessionSpeedup")->Args({9, 12, 4})->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK(BM_SettleRestTo2kPa)->Name("Slow/BM_SettleRestTo2kPa")->Args({9, 12, 4, 1})->Args({9, 12, 10, 0})->Args({9, 12, 10, 1})->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK(BM_SettleOneActionAfter2kPa)->Name("Slow/BM_SettleOneActionAfter2kPa")->Args({9, 12, 4, 0})->Args({9, 12, 4, 1})->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK(BM_SettleCentreJamThenStep)->Name("Slow/BM_SettleCentreJamThenStep")->Args({9, 12, 4, 1})->Unit(benchmark::kMillisecond)->Iterations(1);

}  // namespace
