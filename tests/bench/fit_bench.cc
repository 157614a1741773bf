// The hot paths of a fit: comparing a capture with its frame, and replaying
// a session cold versus warm-started from the settled states of nearby
// parameters (what each Jacobian column does).
#include <benchmark/benchmark.h>

#include <filesystem>

#include "calib/cross_validation.h"
#include "calib/effect_scan.h"
#include "calib/levelling.h"
#include "calib/residuals.h"

namespace {

const std::filesystem::path kBaseline = std::filesystem::path(HJ_SHARED_DIR) / "data/sessions/demo-baseline";

hj::ModelParams true_params() {
  hj::ModelParams p;
  p.surface.mass_kg = 0.52;
  p.surface.spring_k = 58.0;
  p.surface.kappa_jam = 4.2;
  return p;
}

const hj::MeasuredSession& session(const std::string& name) {
  static const hj::Dataset d = hj::read_dataset(kBaseline);
  for (const auto& s : d.sessions)
    if (s.session.name == name) return s;
  throw std::runtime_error("no session " + name);
}

void BM_CompareCapture(benchmark::State& state) {
  const auto& s = session("mixed-1");
  const Eigen::MatrixXd predicted = s.captures[0].heights_mm.array() + 0.5;
  for (auto _ : state) benchmark::DoNotOptimize(hj::compare_capture(predicted, s.captures[0].heights_mm, 1.0));
}
BENCHMARK(BM_CompareCapture)->Unit(benchmark::kMicrosecond);

// Arg: 0 cold, 1 warm-started from the replay at spring_k 1 % lower.
void BM_SessionResiduals(benchmark::State& state, const std::string& name) {
  const auto& s = session(name);
  const hj::ReplayOptions options;
  hj::ModelParams nearby = true_params();
  nearby.surface.spring_k *= 0.99;
  hj::ReplayTrace trace;
  hj::session_residuals(s, nearby, options, nullptr, &trace);
  const hj::ReplayTrace* warm = state.range(0) ? &trace : nullptr;
  for (auto _ : state) benchmark::DoNotOptimize(hj::session_residuals(s, true_params(), options, warm));
}
BENCHMARK_CAPTURE(BM_SessionResiduals, unjammed_sweep, std::string("unjammed-sweep"))->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_SessionResiduals, jammed_sweep, std::string("jammed-sweep"))->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_SessionResiduals, paper_sequence, std::string("paper-sequence"))->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

// Leave-one-session-out of a fitted baseline (calib/cross_validation.h), as
// diagnose judges every model: each fold's checked step replays the other
// sessions, then the held-out one. jammed-sweep, mixed-1, paper-sequence.
void BM_CrossValidation(benchmark::State& state) {
  static const hj::Dataset d =
      hj::select_sessions(hj::read_dataset(kBaseline), {"jammed-sweep", "mixed-1", "paper-sequence"}, true);
  hj::LeastSquaresOptions options;
  options.max_iterations = 6;
  options.replay.threads = 1;
  static const hj::LeastSquaresResult fit = hj::fit_least_squares(d, true_params(), hj::fit_parameters({}), options);
  for (auto _ : state) benchmark::DoNotOptimize(hj::cross_validate(d, hj::fit_parameters({}), fit, options.replay));
}
BENCHMARK(BM_CrossValidation)->Unit(benchmark::kMillisecond);

// The levelling crossing with its 95 % interval (the mass interval of a
// fit), on the demo's unjammed sweep.
void BM_LevellingMass(benchmark::State& state) {
  static const hj::Dataset d = hj::read_dataset(kBaseline);
  for (auto _ : state) benchmark::DoNotOptimize(hj::levelling_mass(d, 9.81));
}
BENCHMARK(BM_LevellingMass)->Unit(benchmark::kMicrosecond);

// diagnose's scan of one candidate (calib/effect_scan.h), bending, from
// `start` on one session:
// - true_baseline: mixed-1 at the true baseline, which has none (the start
//   is kept after the walk up stops at two rises);
// - creased: mixed-3 from a baseline that absorbed a stiff edge in soft
//   jammed cells (kappa_jam 0.114, spring_k 41.4). It creases at the
//   clamped corners near 2 kPa, every bending point has no equilibrium,
//   and the walk ends after two of them.
void BM_EffectScanBending(benchmark::State& state, const std::string& session_name, hj::ModelParams start) {
  const hj::Dataset d = hj::select_sessions(hj::read_dataset(kBaseline), {session_name}, true);
  start = hj::with_effects(start, {"bending"});
  hj::ReplayOptions replay = hj::fitting_replay({});
  replay.threads = 1;
  for (auto _ : state)
    benchmark::DoNotOptimize(hj::scan_effect_start(d, start, hj::fit_parameters({"bending"}), "bending", replay));
}

hj::ModelParams creased_baseline() {
  hj::ModelParams p = true_params();
  p.surface.spring_k = 41.4;
  p.surface.kappa_jam = 0.114;
  return p;
}
BENCHMARK_CAPTURE(BM_EffectScanBending, true_baseline, std::string("mixed-1"), true_params())
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_EffectScanBending, creased, std::string("mixed-3"), creased_baseline())
    ->Unit(benchmark::kMillisecond);

// A multi-start's short fit (2 iterations of the baseline from an off
// start, unjammed-sweep and mixed-1), with its final Jacobian (Arg 1) and
// without it (Arg 0, as diagnose's short fits run): the same end point.
void BM_ShortFit(benchmark::State& state) {
  static const hj::Dataset d =
      hj::select_sessions(hj::read_dataset(kBaseline), {"unjammed-sweep", "mixed-1"}, true);
  hj::ModelParams start = true_params();
  start.surface.mass_kg = 0.50;
  start.surface.spring_k = 64.5;
  hj::LeastSquaresOptions options;
  options.max_iterations = 2;
  options.replay.threads = 1;
  options.replay.fallbacks = false;
  options.final_jacobian = state.range(0) != 0;
  for (auto _ : state) benchmark::DoNotOptimize(hj::fit_least_squares(d, start, hj::fit_parameters({}), options));
}
BENCHMARK(BM_ShortFit)->Arg(1)->Arg(0)->Unit(benchmark::kMillisecond);

// What a replay costs where the model has no equilibrium, as a fit or a
// scan meets it: demo-baseline's mixed-2 with kappa_bend 0.001 N m/rad
// fails at its 3.26 kPa step after the static solver, the implicit flow
// and the fits' short explicit fallback have all run (seconds, against
// about 0.05 s for a replay that settles).
void BM_SlowFailedReplay(benchmark::State& state) {
  const auto& s = session("mixed-2");
  hj::ModelParams p = hj::with_effects(true_params(), {"bending"});
  p.effect_parameters["bending"]["kappa_bend"] = 0.001;
  const hj::ReplayOptions options = hj::fitting_replay({});
  for (auto _ : state) {
    try {
      benchmark::DoNotOptimize(hj::session_residuals(s, p, options));
      state.SkipWithError("the replay settled: no longer a failure case");
    } catch (const std::exception&) {
    }
  }
}
BENCHMARK(BM_SlowFailedReplay)->Unit(benchmark::kMillisecond)->Iterations(1);

}  // namespace
