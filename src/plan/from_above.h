// A planner that reaches every goal from above, as the measurement sessions
// approach levelling (model.md, "States and actions"): raise the pressure
// until every node stands at or above its goal, then lower it step by step,
// pinning each node as it comes down to its goal and jamming each cell as its
// curvature (Eq. 11) comes down to the goal cell's; a step that carries a
// free node more than a tolerance below its goal is backed off and halved.
// Above levelling the dome's height changes smoothly with the pressure,
// whereas rising from the sag the slack net jumps to a tall dome just past
// levelling (algorithm2.cc pins the first nodes far above their goals). The
// run ends with a hill climb over a few end pressures on the score at the
// mesh points (mesh_point_score). See from_above.cc.
#pragma once

#include "plan/planner.h"

namespace hj {

struct FromAboveOptions {
  double decrement_pa = 50.0;     // the downward step, halved on overshoot
  // Bisection stops here. Close to levelling the height goes as the cube
  // root of the net load, so a node whose goal is nearly flat can land
  // further below it than the tolerance.
  double min_step_pa = 1.0;
  // A pin lands within max(pin_tolerance_mm, pin_tolerance_fraction * goal relief).
  double pin_tolerance_mm = 0.5;
  double pin_tolerance_fraction = 0.02;
  double max_pressure_pa = 0.0;   // 0: the device's maximum
  // Throws std::invalid_argument naming the bad field.
  void validate() const;
};

class FromAbove final : public Planner {
 public:
  explicit FromAbove(FromAboveOptions options = {});
  std::string name() const override { return "from-above"; }
  PlanResult plan(const PlanRequest& request, const PlanCallbacks& callbacks = {}) const override;

 private:
  FromAboveOptions options_;
};

}  // namespace hj
