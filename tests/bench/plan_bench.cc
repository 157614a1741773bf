// Planning speed: Algorithm 2 for a real DEM (Maunga Whau) resampled to the
// array. Run: ./build/hj_bench --benchmark_filter=Plan
#include <benchmark/benchmark.h>

#include "plan/planner.h"
#include "shapes/goal_importer.h"
#include "shapes/resample.h"

namespace {

void BM_PlanVolcanoDem(benchmark::State& state) {
  const hj::ArrayGeometry g{static_cast<int>(state.range(0)), static_cast<int>(state.range(1)), 0.038, 4};
  const hj::HeightMap goal = hj::import_goal(HJ_SHARED_DIR "/data/dem/volcano_maunga_whau.csv");
  const hj::PlanRequest request{g, hj::SurfaceParameters::paper_defaults(g), hj::resample_to_mesh(goal, hj::Mesh(g), 30.0), {}};
  const auto planner = hj::make_planner("algorithm2");
  for (auto _ : state) benchmark::DoNotOptimize(planner->plan(request).steps.size());
}

BENCHMARK(BM_PlanVolcanoDem)->Args({3, 4})->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_PlanVolcanoDem)->Name("Slow/BM_PlanVolcanoDem")->Args({9, 12})->Unit(benchmark::kMillisecond)->Iterations(1);

}  // namespace
