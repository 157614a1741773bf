// A planner that runs several strategies on the same goal in parallel and
// keeps the plan whose surface scores best (plan_score: Eq. 12 against the
// goal image when the request has it). The paper's Algorithm 2 is one of
// them, so the result is never worse than Algorithm 2's by that score. The
// others: algorithm2-levelled (algorithm2_levelled.h: no jam below the
// levelling pressure) aiming at 1 and 2 times the goal, and from-above
// (from_above.h). See portfolio.cc.
#pragma once

#include <memory>
#include <vector>

#include "plan/planner.h"

namespace hj {

struct PortfolioOptions {
  // Threads that run strategies at once; 0: one per core.
  int threads = 0;
  // Once Algorithm 2 has finished in T seconds, the other strategies get
  // until max_time_ratio * T (at least min_budget_s) from the start; one still
  // running then is stopped, and the plan it had so far competes with the
  // finished ones. 0: no limit. The aim is at most 5 x Algorithm 2 run on
  // its own, and the ratio leaves room for two things: the same plan's time
  // varies by up to 1.6 x from one run to the next, and at 1 x 2 (plans of
  // a few ms) stopping and scoring the strategies adds about half its time.
  double max_time_ratio = 3.5;
  double min_budget_s = 0.0;
  // And never past this many seconds from the start, so a 9 x 12 plan
  // answers a map viewer within 10 s (Algorithm 2 itself still runs to its
  // end); a strategy whose turn comes later is not started. 0: no cap.
  double max_seconds = 9.0;
  // Throws std::invalid_argument naming the bad field.
  void validate() const;
};

class Portfolio final : public Planner {
 public:
  explicit Portfolio(PortfolioOptions options = {});
  std::string name() const override { return "portfolio"; }
  // Streams the snapshots of the Algorithm 2 strategy as it runs and, at the
  // end, the chosen plan's final state; progress counts finished strategies.
  PlanResult plan(const PlanRequest& request, const PlanCallbacks& callbacks = {}) const override;

  // The strategies, by label, in the order they are started.
  static std::vector<std::pair<std::string, std::unique_ptr<Planner>>> strategies();

 private:
  PortfolioOptions options_;
};

}  // namespace hj
