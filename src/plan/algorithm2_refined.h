// A planner that searches over variants of the paper's Algorithm 2 and keeps
// the one whose surface scores best against the goal at the mesh points
// (mesh_point_score: the correlation, or the height error for a goal in
// absolute millimetres). Each variant is a complete sweep from rest, ended by a scan of
// lower end pressures (with the pins and jams set, the cells between pins
// relax from the bulge that lifting the highest nodes needed; the best end
// pressure is the last step), with these knobs:
//  - height scale: aim for scale * goal. Eq. 12 does not see scale, and the
//    slack net jumps from its sag to a tall dome within a few pascals above
//    the levelling pressure, so with the goal's own (30 mm) relief the first
//    nodes are pinned far above their goals; aiming higher makes that jump
//    a smaller part of the relief;
//  - pressure increment, and bisection of a step that carries a free node
//    past its target, so pins land on their targets;
//  - whether cells may jam below the levelling pressure, where the net still
//    sags (allowed by default: forbidding it measured worse on a centred bump).
// See algorithm2_refined.cc.
#pragma once

#include <string>
#include <vector>

#include "plan/planner.h"

namespace hj {

struct Algorithm2RefinedOptions {
  std::vector<double> height_scales{1.0, 2.0, 3.0};
  std::vector<double> increments_pa{50.0};
  std::vector<bool> jam_below_levelling{true};
  // Back off and halve a pressure step that carries a free node past its
  // target (algorithm2_refined.cc gives the tolerance), so pins land on it.
  std::vector<bool> bisect_pins{true};
  double max_pressure_pa = 0.0;  // 0: the device's maximum
  std::string name = "algorithm2-refined";  // a registered configuration's own name
  // Throws std::invalid_argument naming the bad field.
  void validate() const;
};

class Algorithm2Refined final : public Planner {
 public:
  explicit Algorithm2Refined(Algorithm2RefinedOptions options = {});
  std::string name() const override { return options_.name; }
  PlanResult plan(const PlanRequest& request, const PlanCallbacks& callbacks = {}) const override;

 private:
  Algorithm2RefinedOptions options_;
};

}  // namespace hj
