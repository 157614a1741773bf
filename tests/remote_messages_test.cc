// The CLI's conversions between API messages and files: plan.json steps to a
// Plan (errors naming the file, step and key), and a captured frame compared
// with a predicted surface at the mesh points.
#include <gtest/gtest.h>

#include <cmath>

#include "expect_error.h"
#include "hapticjam/v1/planning_service.pb.h"
#include "remote_messages.h"

namespace hj::cli {
namespace {

namespace v1 = ::hapticjam::v1;
using json = nlohmann::json;

TEST(RemoteMessages, PlanJsonStepsBecomeProtoSteps) {
  const json doc = json::parse(R"({"planner": "algorithm2", "steps": [
      {"op": "set_pressure", "kpa": 0.301}, {"op": "jam", "cell": [0, 3]}, {"op": "pin", "node": [1, 2]},
      {"op": "capture", "frame": "frames/001.csv", "label": "after"}, {"op": "unjam", "cell": [0, 3]},
      {"op": "unpin", "node": [1, 2]}]})");
  const v1::Plan plan = plan_from_steps_json(doc, "plan.json");
  ASSERT_EQ(plan.steps_size(), 6);
  EXPECT_EQ(plan.planner(), "algorithm2");
  EXPECT_EQ(plan.steps(0).set_pressure().kpa(), 0.301);
  EXPECT_EQ(plan.steps(1).jam().row(), 0);
  EXPECT_EQ(plan.steps(1).jam().col(), 3);
  EXPECT_EQ(plan.steps(2).pin().a(), 1);
  EXPECT_EQ(plan.steps(2).pin().b(), 2);
  EXPECT_TRUE(plan.steps(3).has_capture());
  EXPECT_EQ(plan.steps(3).label(), "after");
  EXPECT_EQ(plan.steps(4).unjam().col(), 3);
  EXPECT_EQ(plan.steps(5).unpin().b(), 2);
  // A bare list of steps works too.
  EXPECT_EQ(plan_from_steps_json(doc["steps"], "steps.json").steps_size(), 6);
}

TEST(RemoteMessages, MalformedStepsNameTheFileTheStepAndTheKey) {
  auto bad = [](const char* text, std::vector<std::string> words) {
    testing_support::expect_error<std::invalid_argument>([&] { plan_from_steps_json(json::parse(text), "p.json"); },
                                                         words);
  };
  bad(R"({"plan": []})", {"p.json", "missing key \"steps\""});
  bad(R"({"steps": [{"op": "set_pressure", "kpa": 0.1}, {"op": "set_pressure"}]})", {"p.json", "step 1", "\"kpa\""});
  bad(R"({"steps": [{"op": "set_pressure", "kpa": "high"}]})", {"step 0", "\"kpa\"", "finite number"});
  bad(R"({"steps": [{"op": "jam", "cell": [1]}]})", {"step 0", "\"cell\"", "two whole numbers"});
  bad(R"({"steps": [{"op": "pin", "node": [1.5, 2]}]})", {"step 0", "\"node\""});
  bad(R"({"steps": [{"op": "inflate"}]})", {"step 0", "unknown op \"inflate\""});
  bad(R"({"steps": [{"kpa": 1}]})", {"step 0", "\"op\""});
}

// A frame on a 2 mm grid sampling z = a + b x + c y (mm).
v1::CaptureFrame plane_frame(int nx, int ny, double a, double b, double c) {
  v1::CaptureFrame f;
  auto* g = f.mutable_grid();
  g->set_nx(nx), g->set_ny(ny), g->set_dx_mm(2), g->set_dy_mm(2);
  for (int iy = 0; iy < ny; ++iy)
    for (int ix = 0; ix < nx; ++ix) f.add_heights_mm(a + b * 2 * ix + c * 2 * iy);
  return f;
}

TEST(RemoteMessages, ACaptureOfThePredictedPlaneDiffersByItsOffset) {
  // Mesh points every 9.5 mm over 3 x 4 cells of 38 mm (13 x 17 points), on a 77 x 58 frame.
  Eigen::MatrixXd predicted(13, 17);
  for (int i = 0; i < 13; ++i)
    for (int j = 0; j < 17; ++j) predicted(i, j) = 1.0 + 0.1 * (9.5 * j) - 0.05 * (9.5 * i);
  // A plane is reproduced exactly by bilinear interpolation, so only the offset remains.
  SurfaceDifference d = compare_capture(plane_frame(77, 58, 1.0, 0.1, -0.05), predicted, 9.5);
  EXPECT_EQ(d.points, 13 * 17);
  EXPECT_NEAR(d.rms_mm, 0.0, 1e-9);
  d = compare_capture(plane_frame(77, 58, 3.0, 0.1, -0.05), predicted, 9.5);
  EXPECT_NEAR(d.mean_mm, 2.0, 1e-9);
  EXPECT_NEAR(d.rms_mm, 2.0, 1e-9);
  EXPECT_NEAR(d.max_abs_mm, 2.0, 1e-9);
  // A missing sample drops the mesh points around it, not the whole comparison;
  // points outside a smaller frame are not compared.
  v1::CaptureFrame holed = plane_frame(77, 58, 1.0, 0.1, -0.05);
  holed.set_heights_mm(0, std::nan(""));
  EXPECT_EQ(compare_capture(holed, predicted, 9.5).points, 13 * 17 - 1);
  EXPECT_EQ(compare_capture(plane_frame(39, 58, 1.0, 0.1, -0.05), predicted, 9.5).points, 13 * 9);  // x <= 76 mm
}

TEST(RemoteMessages, ACaptureIsComparedWhereEachPointSits) {
  // Points pulled inwards towards the centre (as a dome pulls them), on the
  // plane z = 1 + 0.1 x - 0.05 y at their displaced positions.
  Eigen::MatrixXd predicted(13, 17), x(13, 17), y(13, 17);
  for (int i = 0; i < 13; ++i)
    for (int j = 0; j < 17; ++j) {
      x(i, j) = 76.0 + 0.9 * (9.5 * j - 76.0);
      y(i, j) = 57.0 + 0.9 * (9.5 * i - 57.0);
      predicted(i, j) = 1.0 + 0.1 * x(i, j) - 0.05 * y(i, j);
    }
  const v1::CaptureFrame frame = plane_frame(77, 58, 1.0, 0.1, -0.05);
  EXPECT_NEAR(compare_capture(frame, predicted, 9.5, &x, &y).rms_mm, 0.0, 1e-9);
  // At the rest positions the same prediction looks wrong by the pull.
  EXPECT_GT(compare_capture(frame, predicted, 9.5).rms_mm, 0.3);  // 0.5 mm here

  v1::SurfaceSnapshot s;
  s.set_point_rows(1), s.set_point_cols(2);
  s.add_heights_mm(1), s.add_heights_mm(2);
  Eigen::MatrixXd sx, sy;
  EXPECT_FALSE(snapshot_positions(s, sx, sy));  // an older server: no positions
  s.add_x_mm(10), s.add_x_mm(20), s.add_y_mm(-1), s.add_y_mm(-2);
  ASSERT_TRUE(snapshot_positions(s, sx, sy));
  EXPECT_EQ(sx(0, 1), 20.0);
  EXPECT_EQ(sy(0, 1), -2.0);
}

TEST(RemoteMessages, GoalHeightsAreRowMajorAndMustMatchTheMesh) {
  v1::PreviewResponse r;
  for (int k = 0; k < 6; ++k) r.add_goal_heights_mm(k);
  const Eigen::MatrixXd g = goal_heights(r.goal_heights_mm(), 2, 3);
  EXPECT_EQ(g(1, 0), 3.0);
  EXPECT_EQ(g(0, 2), 2.0);
  testing_support::expect_error<std::runtime_error>([&] { (void)goal_heights(r.goal_heights_mm(), 3, 3); },
                                                    {"6 heights", "9 mesh points"});
}

TEST(RemoteMessages, SurfacesOfTheWrongSizeAreErrors) {
  v1::SurfaceSnapshot s;
  s.set_point_rows(2), s.set_point_cols(3);
  for (int k = 0; k < 6; ++k) s.add_heights_mm(k);
  const Eigen::MatrixXd m = snapshot_heights(s);
  EXPECT_EQ(m(1, 0), 3.0);  // row-major, row i along +y
  s.add_heights_mm(7);
  testing_support::expect_error<std::runtime_error>([&] { snapshot_heights(s); }, {"7 heights", "2 x 3"});
}

}  // namespace
}  // namespace hj::cli
