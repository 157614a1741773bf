#include "plan/aligned_plan_json.h"

#include <cmath>

namespace hj {
namespace {

nlohmann::json number_or_null(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

nlohmann::json transform_json(const GoalTransform& t, const Region& window) {
  return {{"shift_x_cells", t.shift_x_cells},
          {"shift_y_cells", t.shift_y_cells},
          {"scale", t.scale},
          {"window", {window.x0, window.y0, window.x1, window.y1}}};
}

}  // namespace

nlohmann::json aligned_plan_to_json(const AlignedPlan& plan, bool planned) {
  nlohmann::json doc = transform_json(plan.chosen.transform, plan.chosen.window);
  doc["correlation"] = number_or_null(plan.score);
  doc["unaligned_correlation"] = number_or_null(plan.unaligned_score);
  doc["gain"] = number_or_null(plan.gain());
  if (!planned) return doc;
  doc["candidates"] = plan.candidates;
  doc["planned"] = nlohmann::json::array();
  for (const PlannedCandidate& c : plan.planned) {
    nlohmann::json one = transform_json(c.transform, c.window);
    one["valley_cost"] = c.valley_cost;
    one["correlation"] = number_or_null(c.score);
    one["seconds"] = c.seconds;
    if (!c.error.empty()) one["error"] = c.error;
    doc["planned"].push_back(one);
  }
  return doc;
}

}  // namespace hj
