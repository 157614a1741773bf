// A plan's refused actions (PlanResult::refused) as JSON, for plan.json and
// the server's PlanResult.refused_json: a list of {"action", "reason",
// "after_step"}.
#pragma once

#include <nlohmann/json.hpp>
#include <vector>

#include "plan/planner.h"

namespace hj {

nlohmann::json refused_to_json(const std::vector<RefusedAction>& refused);

}  // namespace hj
