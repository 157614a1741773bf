#include "planning.h"

#include "metrics/laplace_predictor.h"
#include "shapes/resample.h"
#include "sim/surface_measures.h"

namespace hj::server {

PlanningOutput run_planning(const PlanningInput& input, const PlanCallbacks& callbacks) {
  const auto planner = make_planner(input.planner);
  const Mesh mesh(input.array.geometry);
  PlanningOutput out;
  out.planner = planner->name();
  PlanRequest request{input.array.geometry, input.array.params,
                      goal_to_mesh(input.goal, mesh, input.heights, input.max_height_mm),
                      input.array.simulator, input.goal.z};
  if (input.heights == GoalHeights::kAbsolute) request.scoring = PlanScoring::kHeightError;
  out.result = planner->plan(request, callbacks);
  out.goal_mm = std::move(request.goal_mm);
  out.predicted_mm = point_heights(mesh, out.result.final_state.x) * 1000.0;
  // Mesh row i runs along +y; an image's row 0 is its top: flip to compare.
  out.correlation = correlate_with_goal(input.goal.z, out.predicted_mm.colwise().reverse());
  out.laplace_mean = laplace_mean(input.goal.z);
  return out;
}

}  // namespace hj::server
