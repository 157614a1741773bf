// Planning speed: Algorithm 2 for a real DEM (Maunga Whau) resampled to the
// array, a GeoTIFF DEM, the sweep of one goal over array sizes, and scoring
// a plan against its goal image (the portfolio scores every strategy's).
// Run: ./build/hj_bench --benchmark_filter="^BM_(Plan|Sweep)"
#include <benchmark/benchmark.h>

#include <cmath>
#include <exception>

#include "plan/planner.h"
#include "plan/sweep.h"
#include "shapes/goal_importer.h"
#include "shapes/resample.h"

namespace {

// One plan; a plan that finds no equilibrium (9 x 12 Algorithm 2, 6 x 8
// from-above: mesh folds, see README) is reported, not a crash.
void plan_once(benchmark::State& state, const hj::Planner& planner, const hj::PlanRequest& request) {
  try {
    const hj::PlanResult result = planner.plan(request);
    state.counters["steps"] = double(result.steps.size());
  } catch (const std::exception& e) {
    state.SkipWithError(e.what());
  }
}

void BM_PlanVolcanoDem(benchmark::State& state) {
  const hj::ArrayGeometry g{static_cast<int>(state.range(0)), static_cast<int>(state.range(1)), 0.038, 4};
  const hj::HeightMap goal = hj::import_goal(HJ_SHARED_DIR "/data/dem/volcano_maunga_whau.csv");
  const hj::PlanRequest request{g, hj::SurfaceParameters::paper_defaults(g), hj::resample_to_mesh(goal, hj::Mesh(g), 30.0), {}, {}};
  const auto planner = hj::make_planner("algorithm2");
  for (auto _ : state) plan_once(state, *planner, request);
}

BENCHMARK(BM_PlanVolcanoDem)->Args({3, 4})->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_PlanVolcanoDem)->Name("Slow/BM_PlanVolcanoDem")->Args({6, 8})->Args({9, 12})->Unit(benchmark::kMillisecond)->Iterations(1);

// plan_score (Eq. 12 against the goal image) of a predicted surface: the
// Jacksboro DEM (the largest shared image) and a dome, at 1 x 2 and 9 x 12.
void BM_PlanScore(benchmark::State& state) {
  const hj::ArrayGeometry g{static_cast<int>(state.range(0)), static_cast<int>(state.range(1)), 0.038, 4};
  const hj::HeightMap goal = hj::import_goal(HJ_SHARED_DIR "/data/dem/jacksboro_fault_tn.csv");
  const hj::Mesh mesh(g);
  const hj::PlanRequest request{g, hj::SurfaceParameters::paper_defaults(g), hj::resample_to_mesh(goal, mesh, 30.0),
                                {}, goal.z};
  hj::DeviceState dome;
  dome.x = mesh.rest_positions();
  for (int i = 0; i < dome.x.cols(); ++i) dome.x(2, i) = 0.01 * std::sin(3.0 * dome.x(0, i)) * std::cos(5.0 * dome.x(1, i));
  for (auto _ : state) benchmark::DoNotOptimize(hj::plan_score(request, mesh, dome));
  state.counters["pixels"] = double(goal.z.size());
}
BENCHMARK(BM_PlanScore)->Args({1, 2})->Args({9, 12})->Unit(benchmark::kMicrosecond);

// The from-above planner (src/plan/from_above.h) on the same DEM.
void BM_PlanVolcanoDemFromAbove(benchmark::State& state) {
  const hj::ArrayGeometry g{static_cast<int>(state.range(0)), static_cast<int>(state.range(1)), 0.038, 4};
  const hj::HeightMap goal = hj::import_goal(HJ_SHARED_DIR "/data/dem/volcano_maunga_whau.csv");
  const hj::PlanRequest request{g, hj::SurfaceParameters::paper_defaults(g), hj::resample_to_mesh(goal, hj::Mesh(g), 30.0), {}, {}};
  const auto planner = hj::make_planner("from-above");
  for (auto _ : state) plan_once(state, *planner, request);
}
BENCHMARK(BM_PlanVolcanoDemFromAbove)->Args({3, 4})->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK(BM_PlanVolcanoDemFromAbove)
    ->Name("Slow/BM_PlanVolcanoDemFromAbove")
    ->Args({6, 8})
    ->Args({9, 12})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1);

}  // namespace

namespace {

// The sweep of one goal (Maunga Whau, north-up by its sidecar) at the small
// array sizes, on all cores; Slow/: the whole Table 1 list.
void BM_SweepVolcano(benchmark::State& state, const char* sizes) {
  const std::vector<hj::SweepGoal> goals{
      {"volcano", hj::import_goal(HJ_SHARED_DIR "/data/dem/volcano_maunga_whau.csv")}};
  hj::SweepOptions options;
  options.sizes = hj::parse_array_sizes(sizes);
  int ok = 0;
  for (auto _ : state) {
    ok = 0;
    for (const auto& row : hj::run_sweep(goals, options)) ok += row.status == "ok";
  }
  state.counters["plans_ok"] = ok;
}

BENCHMARK_CAPTURE(BM_SweepVolcano, small, "2x2,3x4,4x6")->Unit(benchmark::kMillisecond)->Iterations(1)->UseRealTime();
BENCHMARK_CAPTURE(BM_SweepVolcano, paper, "paper")
    ->Name("Slow/BM_SweepVolcano/paper")
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1)
    ->UseRealTime();

// One GeoTIFF DEM (Luxembourg, through GDAL, no-data outside the border) at 3 x 4.
void BM_PlanLuxembourgGeoTiff(benchmark::State& state) {
  const hj::ArrayGeometry g{3, 4, 0.038, 4};
  const hj::HeightMap goal = hj::import_goal(HJ_SHARED_DIR "/data/dem/luxembourg_elev.tif");
  const hj::PlanRequest request{g, hj::SurfaceParameters::paper_defaults(g), hj::resample_to_mesh(goal, hj::Mesh(g), 30.0), {}, {}};
  const auto planner = hj::make_planner("algorithm2");
  for (auto _ : state) benchmark::DoNotOptimize(planner->plan(request).steps.size());
}
BENCHMARK(BM_PlanLuxembourgGeoTiff)->Unit(benchmark::kMillisecond)->Iterations(3);

}  // namespace
