#include "calib/step_json.h"

namespace hj {

nlohmann::json action_to_step_json(const Action& action) {
  nlohmann::json step = {{"op", action.op_name()}};
  switch (action.op) {
    case Action::Op::kSetPressure:
      step["kpa"] = action.pressure_pa / 1000.0;
      break;
    case Action::Op::kJam:
    case Action::Op::kUnjam:
      step["cell"] = {action.a, action.b};
      break;
    case Action::Op::kPin:
    case Action::Op::kUnpin:
      step["node"] = {action.a, action.b};
      break;
  }
  return step;
}

}  // namespace hj
