#include "render_expectation.h"

#include "metrics/correction_screen.h"
#include "metrics/height_error.h"
#include "render_frames.h"

namespace hj::server {

void RenderExpectation::after_run(const Eigen::MatrixXd& measured, const Eigen::MatrixXd& predicted,
                                  const hapticjam::v1::CaptureGrid& grid) {
  last_measured_ = measured, last_predicted_ = predicted, last_grid_ = grid;
  misfit_applies_ = true;
}

RenderExpectation::Expected RenderExpectation::of(const PlanResult& planned) const {
  Expected out;
  out.surface = predicted_at_rest_points(mesh_, planned.final_state.x, last_grid_);
  if (misfit_applies_) out.surface = expected_outcome(out.surface, last_measured_, last_predicted_);
  out.mae_mm = height_error(goal_mm_, out.surface).mae_mm;
  return out;
}

}  // namespace hj::server
