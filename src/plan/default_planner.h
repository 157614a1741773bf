// The planner that plan, sweep, the server and the render loop use when a
// request names none.
#pragma once

namespace hj {

inline constexpr const char* kDefaultPlanner = "algorithm2";

}  // namespace hj
