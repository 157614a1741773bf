// Planning an aligned goal (shapes/goal_alignment.h): the unaligned goal and
// the few candidate windows whose valleys the criterion puts closest to the
// nodes are planned, and the plan with the best plan_score (Eq. 12 against
// its own window of the goal) is kept. The identity is always planned, so
// the result is never worse than the unaligned plan by that score.
#pragma once

#include <cmath>
#include <string>
#include <vector>

#include "plan/planner.h"
#include "shapes/goal_alignment.h"

namespace hj {

struct AlignedPlanOptions {
  AlignOptions align;
  // Candidates planned besides the identity: the lowest valley costs, and
  // only those below the identity's (valleys already on nodes: none), >= 0.
  int plans = 3;
  int threads = 0;  // plans run in parallel; 0: one per core
  // A candidate's plan is stopped (and not chosen) once it has run this many
  // times as long as the unaligned goal's plan (at least 1 s), so a window
  // that drives the planner into slow dead ends costs a bounded time; >= 1.
  double max_time_ratio = 3.0;
  // How the candidates planned besides the identity are picked: by valley
  // cost, or (a control, to measure what the criterion adds over trying
  // `plans` other windows) uniformly at random among all, seeded by `seed`.
  enum class Pick { kValleyCost, kRandom };
  Pick pick = Pick::kValleyCost;
  unsigned seed = 1;
  // @throws std::invalid_argument naming the field (AlignedPlanOptions.plans, AlignOptions.*).
  void validate() const;
};

struct PlannedCandidate {
  GoalTransform transform;
  Region window;
  double valley_cost = 0.0;
  double score = 0.0;  // plan_score; -inf when undefined or the plan failed
  std::string error;   // why its plan failed or was stopped, if it was
  double seconds = 0.0;
};

struct AlignedPlan {
  AlignmentCandidate chosen;     // its transform, window and goal at the mesh points
  HeightMap goal;                // the chosen window of the source, scored against (Eq. 12)
  PlanResult result;             // the plan of the chosen goal
  double score = 0.0;            // its plan_score
  double unaligned_score = 0.0;  // the identity's plan_score
  // score - unaligned_score; NaN when either is undefined.
  double gain() const {
    return std::isfinite(score) && std::isfinite(unaligned_score) ? score - unaligned_score : NAN;
  }
  int candidates = 0;                    // distinct windows on the grid inside the source
  std::vector<PlannedCandidate> planned;  // the identity first
};

// Plans `source`'s `window` (a pixel region of it) aligned on request.geometry
// with planner `planner`: request carries the geometry, parameters and
// simulator options (its goal fields are replaced); relief_mm is the goal
// relief. Ties go to the identity, then to the lower valley cost.
// @throws std::invalid_argument on bad options, window, relief or planner
//         name; PlanCancelled when cancelled; the identity's plan error if it
//         fails (another candidate's failure is recorded in `planned`).
AlignedPlan plan_aligned(const std::string& planner, const HeightMap& source, const Region& window,
                         const PlanRequest& request, double relief_mm, const AlignedPlanOptions& options,
                         const PlanCallbacks& callbacks = {});

}  // namespace hj
