// One planning request, start to finish, in library calls only: resample the
// goal to the mesh, run the planner (with progress, snapshots and
// cancellation), score the predicted surface against the goal image
// (correlation, paper Eq. 12) and the goal itself (Laplace mean, Eq. 14).
#pragma once

#include <Eigen/Core>
#include <string>

#include "metrics/correlation.h"
#include "plan/default_planner.h"
#include "plan/planner.h"
#include "proto_convert.h"
#include "shapes/height_map.h"
#include "shapes/resample.h"

namespace hj::server {

struct PlanningInput {
  ArrayConfig array;
  HeightMap goal;
  double max_height_mm = 0.0;  // 0: the array's default relief
  std::string planner = kDefaultPlanner;
  GoalHeights heights = GoalHeights::kScaled;
};

struct PlanningOutput {
  std::string planner;           // the planner's own name
  PlanResult result;
  Eigen::MatrixXd goal_mm;       // the goal per mesh point, (R p + 1) x (C p + 1)
  Eigen::MatrixXd predicted_mm;  // the predicted surface per mesh point, same shape
  Correlation correlation;       // predicted vs the goal image
  double laplace_mean = 0.0;     // of the goal image
};

// @throws std::invalid_argument (unknown planner, bad goal), hj::PlanCancelled.
PlanningOutput run_planning(const PlanningInput& input, const PlanCallbacks& callbacks);

}  // namespace hj::server
