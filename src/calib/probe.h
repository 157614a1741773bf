// The probe a render fits its device model on (docs/render.md): the free
// membrane, nothing jammed or pinned, raised from rest through a few
// pressures, captured at rest and at each. Where it starts and stops.
#pragma once

#include <vector>

#include "calib/model_params.h"
#include "calib/residuals.h"

namespace hj {

// `levels` pressures evenly spaced from `from_pa` to `to_pa`.
// @throws std::invalid_argument unless 0 < from_pa <= to_pa and levels >= 1.
std::vector<Action> probe_actions(double from_pa, double to_pa, int levels);

// The highest pressure at which `plan` jams or pins (its highest pressure if
// it does neither): past it a plan's pressure only moves its free cells.
double shaping_pressure_pa(const std::vector<Action>& plan);

// The probe after `plan` ran, in four levels: from `from_pa` up to the
// plan's shaping pressure, or lower, where the free membrane of `model`
// domes to 1.5 x `goal_top_mm` (at least twice from_pa, at most the
// model's pressure limit). A probe far above the goal's heights (a free
// 6 x 8 dome at 3 kPa, 150 mm, for a goal of 84 mm) is where the baseline
// model is furthest from a stiffening device (39 mm RMSE), every candidate
// passes against it, and the fit of them all is slow.
// @throws SettleInterrupted when replay.interrupted says so.
std::vector<Action> probe_for_plan(const ArrayGeometry& geometry, const ModelParams& model, const ReplayOptions& replay,
                                   double from_pa, const std::vector<Action>& plan, double goal_top_mm);

}  // namespace hj
