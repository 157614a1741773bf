#include "plan/refused_json.h"

namespace hj {

nlohmann::json refused_to_json(const std::vector<RefusedAction>& refused) {
  nlohmann::json out = nlohmann::json::array();
  for (const RefusedAction& r : refused)
    out.push_back({{"action", r.action.describe()}, {"reason", r.reason}, {"after_step", r.after_step}});
  return out;
}

}  // namespace hj
