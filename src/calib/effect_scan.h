// A coarse scan for where a candidate effect's fit should start. A local
// fit (screening's Gauss-Newton step, the refit's Levenberg-Marquardt)
// from the effect's registry defaults can stop far from the data's optimum
// when the model answers the parameter very nonlinearly: on demo-bending,
// from kappa_bend = 0 the screening predicted 1.7e-6 N m/rad and the refit
// stopped at 0.00055, while 0.003 already lowers the RMSE from 2.78 to
// 1.88 mm and a fit from there reaches the truth, 0.002. Between them, no
// replay settles for kappa_bend 0.001 .. 0.0014 (a limit point).
//
// Each of the effect's parameters is moved alone from the start toward
// each bound, to 0.1 %, 0.3 %, 1 %, 3 %, 10 %, 30 %, 70 %, 90 %, 97 % and
// 100 % of the way, and the dataset replayed there; a direction stops once
// two replays in a row cost more than the best before them. Points where
// the model has no equilibrium (by default: that the static solver cannot
// settle without the fallbacks) are stepped over; a start that does not
// replay gives way to the best scanned point that does. Every point is
// replayed cold (effect_scan.cc says why). The directions run in parallel
// (with fewer directions than threads, each point's sessions too). A
// measurement effect's points (a camera tilt) share their surfaces, so the
// dataset is replayed once for all of them.
#pragma once

#include <string>
#include <vector>

#include "calib/fit_parameters.h"
#include "calib/residuals.h"

namespace hj {

struct EffectScan {
  ModelParams best;           // the start, or the scanned point of lowest cost
  double start_sum_sq_mm2 = 0.0;
  double best_sum_sq_mm2 = 0.0;
  bool moved = false;         // best is a scanned point, a real margin below the start
  int replays = 0;            // whole-dataset replays it cost
  int failed = 0;             // points where the model has no equilibrium
  std::string note;           // e.g. "bending.kappa_bend 0 -> 0.003 (SSR -54 %)"
};

struct EffectScanOptions {
  // A scanned point is taken only if it lowers the sum of squares by this
  // share of the start's: less is what noise moves it by.
  double min_gain = 0.01;
  // The far side too: a start that is not neutral (area_pressure's weight
  // 1 toward 0) may have the data's value near the other bound (0.1).
  std::vector<double> fractions = {1e-3, 3e-3, 1e-2, 3e-2, 0.1, 0.3, 0.7, 0.9, 0.97, 1.0};
  // The scanned points (not the start) are replayed with the simulator's
  // fallbacks (ReplayOptions::fallbacks); off, a point only they could
  // settle counts as one with no equilibrium.
  bool fallbacks = false;
  // A measurement-only effect (EffectInfo::measurement_only) is scanned on
  // one replay of the dataset (measurement_effects.h), with the same
  // figures; off, every point is replayed (the tests compare the two).
  bool reuse_measurement_replays = true;
};

// @param start  the current model's optimum with `effect` switched on at its
//               start values
// @throws std::runtime_error if the dataset replays neither at `start` nor
//         at any scanned point
EffectScan scan_effect_start(const Dataset& dataset, const ModelParams& start,
                             const std::vector<FitParameter>& parameters, const std::string& effect,
                             const ReplayOptions& replay, const EffectScanOptions& options = {});

}  // namespace hj
