// The seed paper's Algorithm 2 (pressure sweep with pin-at-height and
// jam-at-curvature), exactly as published; see algorithm2.cc.
#pragma once

#include "plan/planner.h"

namespace hj {

struct Algorithm2Options {
  double pressure_increment_pa = 50.0;
  double max_pressure_pa = 0.0;  // 0: the device's maximum
};

class Algorithm2 final : public Planner {
 public:
  explicit Algorithm2(Algorithm2Options options = {});
  std::string name() const override { return "algorithm2"; }
  PlanResult plan(const PlanRequest& request, const PlanCallbacks& callbacks = {}) const override;

 private:
  Algorithm2Options options_;
};

}  // namespace hj
