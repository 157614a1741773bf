// Actions as session-format steps (docs/session-format.md): the JSON a plan
// writes so that `hapticjam simulate` and a device can replay it.
#pragma once

#include <nlohmann/json.hpp>

#include "model/action.h"

namespace hj {

// {"op": "set_pressure", "kpa": 0.301}, {"op": "jam", "cell": [r, c]}, ...
nlohmann::json action_to_step_json(const Action& action);

}  // namespace hj
