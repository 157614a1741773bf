#include "calib/optimum_probe.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "calib/parallel_for.h"

namespace hj {

OptimumProbe probe_optimum(const Dataset& dataset, const LeastSquaresResult& fit, const ReplayOptions& replay,
                           const OptimumProbeOptions& options) {
  struct Point {
    const ParameterEstimate* estimate;
    double value;
    double sum_sq = std::numeric_limits<double>::infinity();
  };
  std::vector<Point> points;
  for (const ParameterEstimate& e : fit.estimates) {
    if (!e.active || !(e.std_error > 0.0) || !std::isfinite(e.std_error)) continue;
    for (double sign : {1.0, -1.0}) {
      const double bound = sign > 0.0 ? e.parameter.spec.upper : e.parameter.spec.lower;
      const double room = std::abs(bound - e.value);
      if (!(room > 0.0)) continue;
      bool past_bound = false;
      for (double m : options.multiples) {
        if (m * e.std_error < room)
          points.push_back({&e, e.value + sign * m * e.std_error});
        else
          past_bound = true;
      }
      // A loose parameter's multiples all land on the bound: the probe
      // looks between the optimum and the bound instead.
      if (past_bound)
        for (double f : options.bound_fractions) points.push_back({&e, e.value + sign * f * room});
    }
  }
  OptimumProbe out;
  out.best = fit.params;
  out.start_sum_sq_mm2 = out.best_sum_sq_mm2 = fit.sum_sq_mm2;
  out.points = static_cast<int>(points.size());
  // A point above this is never taken, so its replay may stop there.
  const double worth_taking = (1.0 - options.min_gain) * fit.sum_sq_mm2;
  // Each point's replay moves each step as the optimum's replay moved it
  // (replay_session's warm start): one replay more, every point cheaper.
  std::vector<ReplayTrace> at_optimum;
  if (out.points > 1)
    dataset_sum_of_squares(dataset, fit.params, replay, replay.threads > 0 ? replay.threads : default_thread_count(),
                           std::numeric_limits<double>::infinity(), nullptr, &at_optimum);
  parallel_for(
      out.points,
      [&](int k) {
        ModelParams at = fit.params;
        set_parameter_value(at, points[k].estimate->parameter, points[k].value);
        points[k].sum_sq = dataset_sum_of_squares(dataset, at, replay, 1, worth_taking, &at_optimum);
      },
      replay.threads);
  const Point* best = nullptr;
  for (const Point& p : points) {
    if (!std::isfinite(p.sum_sq)) ++out.failed;
    else if (p.sum_sq < out.best_sum_sq_mm2) {
      out.best_sum_sq_mm2 = p.sum_sq;
      best = &p;
    }
  }
  const double gain = 1.0 - out.best_sum_sq_mm2 / out.start_sum_sq_mm2;
  if (!best || !(gain >= options.min_gain)) {
    out.best_sum_sq_mm2 = out.start_sum_sq_mm2;
    return out;
  }
  set_parameter_value(out.best, best->estimate->parameter, best->value);
  out.moved = true;
  out.note = parameter_move_note(best->estimate->parameter, best->estimate->value, best->value, gain);
  return out;
}

}  // namespace hj
