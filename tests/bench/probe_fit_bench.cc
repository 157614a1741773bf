// The render's calibration on the fly (docs/render.md): the device model
// fitted on a probe (the free membrane at four pressures, captured at rest
// and at each) with the render's options, at 3 x 4 and 6 x 8. The probe is
// the model's own (stiffening, beta 30) with a 1 mm camera.
#include <benchmark/benchmark.h>

#include <random>

#include "calib/on_the_fly.h"
#include "calib/probe.h"
#include "calib/replay.h"
#include "calib/synthesize.h"

namespace {

hj::Dataset stiffening_probe(const hj::ArrayGeometry& geometry) {
  hj::ModelParams device;
  device.surface = hj::SurfaceParameters::paper_defaults(geometry);
  device = hj::with_effects(device, {"stiffening"});
  device.effect_parameters["stiffening"]["beta"] = 30.0;
  const hj::SessionDevice shape{geometry.rows, geometry.cols, geometry.cell_size_m * 1000.0, 3.45};
  hj::SessionGrid grid;
  grid.dx_mm = grid.dy_mm = 2.0;
  grid.nx = int(geometry.cols * geometry.cell_size_m * 1000.0 / 2.0) + 1;
  grid.ny = int(geometry.rows * geometry.cell_size_m * 1000.0 / 2.0) + 1;
  const std::vector<hj::Action> probe = hj::probe_actions(467.0, 1700.0, 4);
  const Eigen::MatrixXd blank = Eigen::MatrixXd::Zero(grid.ny, grid.nx);
  std::vector<hj::RunCapture> captures;
  for (size_t k = 0; k <= probe.size(); ++k) captures.push_back({k, blank});
  hj::MeasuredSession session = hj::captured_session("probe", shape, grid, probe, captures);
  const auto predicted = hj::replay_session(session.session, geometry.segments, device.surface,
                                            hj::simulator_options(device, hj::ReplayOptions{}));
  std::mt19937_64 rng(3);
  for (size_t k = 0; k < session.captures.size(); ++k)
    session.captures[k].heights_mm = hj::add_camera_noise(predicted[k].heights_mm, hj::SynthOptions{}, rng);
  hj::Dataset out;
  out.sessions.push_back(std::move(session));
  return out;
}

// Arg: rows (3: 3 x 4, 6: 6 x 8). The render's options: 50 iterations, no fallbacks, 2 threads.
void BM_ProbeFit(benchmark::State& state) {
  const hj::ArrayGeometry geometry{int(state.range(0)), int(state.range(0)) * 4 / 3, 0.038, 4};
  const hj::Dataset probe = stiffening_probe(geometry);
  hj::ModelParams start;
  start.surface = hj::SurfaceParameters::paper_defaults(geometry);
  hj::OnTheFlyOptions options;
  options.replay.threads = 2;
  options.replay.fallbacks = false;
  options.max_iterations = 50;
  for (auto _ : state) {
    const hj::OnTheFlyFit fit = hj::calibrate_on_the_fly(probe, start, options);
    state.counters["replays"] = fit.replays;
    state.counters["rmse_mm"] = fit.rmse_mm;
  }
}
BENCHMARK(BM_ProbeFit)->Arg(3)->Arg(6)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
