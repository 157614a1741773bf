#include "calib/effect_scan.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <optional>
#include <stdexcept>

#include "calib/least_squares.h"
#include "calib/measurement_effects.h"
#include "calib/parallel_for.h"

namespace hj {

namespace {

struct Direction {
  FitParameter parameter;
  double from = 0.0, to = 0.0;  // the start value and the bound it walks to
};

struct DirectionResult {
  double best_sum_sq = std::numeric_limits<double>::infinity();
  double value = 0.0;
  int replays = 0, failed = 0;  // points costed, and of them with no equilibrium
};

// The sum of squares at a scanned point (infinity: no equilibrium).
using PointCost = std::function<double(const ModelParams&)>;

// Walks one direction, each point costed by `cost` (a replay of the
// dataset, or a measurement effect's reused one). A point's replay moves
// each step as the start's replay moved it (replay_session's warm start),
// which costs less than a cold replay even 3 x away (docs/calibration.md).
// Two rises in a row end the walk; a point with no equilibrium counts as
// one once the start or a point has replayed (before that, as from a start
// with no equilibrium, it is stepped over).
DirectionResult walk(const ModelParams& start, bool start_replays, const Direction& d,
                     const EffectScanOptions& options, const PointCost& cost) {
  DirectionResult out;
  int rises = 0;
  for (double fraction : options.fractions) {
    const double value = d.from + fraction * (d.to - d.from);
    ModelParams point = start;
    set_parameter_value(point, d.parameter, value);
    const double sum_sq = cost(point);
    ++out.replays;
    if (!std::isfinite(sum_sq)) {
      ++out.failed;
      const bool replayed_before = start_replays || std::isfinite(out.best_sum_sq);
      if (replayed_before && ++rises == 2) break;
      continue;
    }
    if (sum_sq < out.best_sum_sq) {
      out.best_sum_sq = sum_sq;
      out.value = value;
      rises = 0;
    } else if (++rises == 2) {
      break;
    }
  }
  return out;
}

}  // namespace

EffectScan scan_effect_start(const Dataset& dataset, const ModelParams& start,
                             const std::vector<FitParameter>& parameters, const std::string& effect,
                             const ReplayOptions& replay, const EffectScanOptions& options) {
  EffectScan out;
  out.best = start;
  std::vector<Direction> directions;
  for (const auto& p : parameters) {
    if (p.surface || p.effect != effect) continue;
    const double v = parameter_value(start, p);
    if (v > p.spec.lower) directions.push_back({p, v, p.spec.lower});
    if (v < p.spec.upper) directions.push_back({p, v, p.spec.upper});
  }
  std::vector<DirectionResult> results(directions.size() + 1);
  // Result 0 is the start itself, replayed first on every thread; then the
  // directions in parallel, and with fewer directions than threads each
  // point's sessions too (a one-parameter effect at its bound has a single
  // direction, which would otherwise run on one core).
  const int threads = replay.threads > 0 ? replay.threads : default_thread_count();
  // A point is only a candidate start, so one the static solver cannot
  // settle is stepped over at once rather than after the fallbacks (a
  // failed replay with them is the costliest kind, and most of a scan's
  // time where the start sits next to a region with no equilibrium).
  ReplayOptions point_replay = replay;
  point_replay.fallbacks = options.fallbacks;
  const int session_threads = std::max(1, threads / std::max(1, static_cast<int>(directions.size())));
  bool start_replays = false;
  if (options.reuse_measurement_replays && is_measurement_only(effect)) {
    // Every point simulates the same surfaces: the dataset is replayed once
    // with the start's options and once with the points' (they may settle
    // differently), and the points cost no replay.
    ReplayOptions start_replay = replay;
    start_replay.threads = threads;
    const CameraFreeReplay at_start(dataset, start, start_replay);
    results[0].best_sum_sq = at_start.sum_of_squares(start);
    start_replays = std::isfinite(results[0].best_sum_sq);
    out.replays = 1;
    std::optional<CameraFreeReplay> own;
    if (point_replay.fallbacks != replay.fallbacks) {
      point_replay.threads = threads;
      own.emplace(dataset, start, point_replay);
      ++out.replays;
    }
    const CameraFreeReplay& at_points = own ? *own : at_start;
    for (size_t k = 0; k < directions.size(); ++k)
      results[k + 1] = walk(start, start_replays, directions[k], options,
                            [&](const ModelParams& p) { return at_points.sum_of_squares(p); });
    for (const auto& r : results) out.failed += r.failed;
  } else {
    std::vector<ReplayTrace> start_traces;
    results[0].best_sum_sq = dataset_sum_of_squares(dataset, start, replay, threads,
                                                    std::numeric_limits<double>::infinity(), nullptr, &start_traces);
    results[0].replays = 1;
    start_replays = std::isfinite(results[0].best_sum_sq);
    parallel_for(
        static_cast<int>(directions.size()),
        [&](int k) {
          results[k + 1] = walk(start, start_replays, directions[k], options, [&](const ModelParams& p) {
            return dataset_sum_of_squares(dataset, p, point_replay, session_threads,
                                          std::numeric_limits<double>::infinity(), &start_traces);
          });
        },
        replay.threads);
    for (const auto& r : results) {
      out.replays += r.replays;
      out.failed += r.failed;
    }
  }
  out.start_sum_sq_mm2 = out.best_sum_sq_mm2 = results[0].best_sum_sq;
  int best = -1;
  for (size_t k = 1; k < results.size(); ++k)
    if (results[k].best_sum_sq < out.best_sum_sq_mm2) {
      out.best_sum_sq_mm2 = results[k].best_sum_sq;
      best = static_cast<int>(k);
    }
  // A start that does not replay (area_pressure's default, weight 1, has
  // no equilibrium at 2 kPa) gives way to any scanned point that does.
  if (!start_replays && best < 0)
    throw std::runtime_error("the model fails to replay the dataset with " + effect +
                             " at its start values and at every scanned point");
  const double gain = start_replays ? 1.0 - out.best_sum_sq_mm2 / out.start_sum_sq_mm2 : 1.0;
  if (best < 0 || gain < options.min_gain) {
    out.best_sum_sq_mm2 = out.start_sum_sq_mm2;
    return out;
  }
  const Direction& d = directions[best - 1];
  set_parameter_value(out.best, d.parameter, results[best].value);
  out.moved = true;
  out.note = parameter_move_note(d.parameter, d.from, results[best].value,
                                 start_replays ? std::optional<double>(gain) : std::nullopt);
  return out;
}

}  // namespace hj
