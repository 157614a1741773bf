// The render's probe (server/render_calibration.h): the free membrane from
// the levelling margin up to the pressures that shaped the first run, or
// lower where the model's dome already covers the goal's heights.
#include "render_calibration.h"

#include <gtest/gtest.h>

namespace hj::server {
namespace {

const ArrayGeometry kGeometry{3, 4, 0.038, 4};

ModelParams baseline() {
  ModelParams p;
  p.surface = SurfaceParameters::paper_defaults(kGeometry);
  return p;
}

double top_of(const std::vector<Action>& probe) { return probe.back().pressure_pa; }

const std::vector<Action> kPlan = {Action::set_pressure(1000), Action::jam(0, 0), Action::set_pressure(3000),
                                   Action::pin(1, 1), Action::set_pressure(3450)};

TEST(RenderProbe, RisesToThePressureAtWhichThePlanLastJamsOrPinsForATallGoal) {
  const RenderCalibration calibration(kGeometry, baseline(), 1, {});
  const std::vector<Action> probe = calibration.probe(1.5, kPlan, 200.0);
  ASSERT_EQ(probe.size(), 4u);
  const double levelling = baseline().surface.levelling_pressure_pa(Mesh(kGeometry));
  EXPECT_NEAR(probe.front().pressure_pa, 1.5 * levelling, 1e-9);
  EXPECT_NEAR(top_of(probe), 3000.0, 1e-9);
  for (size_t k = 1; k < probe.size(); ++k) EXPECT_GT(probe[k].pressure_pa, probe[k - 1].pressure_pa);
}

TEST(RenderProbe, StopsWhereTheModelsFreeDomeCoversALowGoalWithMargin) {
  const RenderCalibration calibration(kGeometry, baseline(), 1, {});
  const double levelling = baseline().surface.levelling_pressure_pa(Mesh(kGeometry));
  const double low = top_of(calibration.probe(1.5, kPlan, 25.0));
  EXPECT_LT(low, 3000.0);
  EXPECT_GE(low, 2.0 * 1.5 * levelling - 1e-9);  // at least twice its first level
  EXPECT_LT(low, top_of(calibration.probe(1.5, kPlan, 40.0)));
}

}  // namespace
}  // namespace hj::server
