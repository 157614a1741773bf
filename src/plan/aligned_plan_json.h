// An aligned plan's transform and gain (plan/aligned_plan.h) as JSON, for
// plan.json's "align" block and the --json summary.
#pragma once

#include <nlohmann/json.hpp>

#include "plan/aligned_plan.h"

namespace hj {

// {"shift_x_cells", "shift_y_cells", "scale", "window": [x0, y0, x1, y1]
// (pixels of the goal as imported), "correlation", "unaligned_correlation",
// "gain" (null when undefined)}; with `planned`, also "candidates" (windows
// on the grid) and "planned": per goal planned, its transform, window,
// valley_cost, correlation, seconds and any error.
nlohmann::json aligned_plan_to_json(const AlignedPlan& plan, bool planned = true);

}  // namespace hj
