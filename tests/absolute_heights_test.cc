// Goals in absolute millimetres (--heights absolute, GOAL_HEIGHTS_ABSOLUTE):
// a table of exactly the mesh's points is the goal at those points, any other
// size is averaged without rescaling, negative heights stay negative, and the
// formats whose values are not mm are refused by name.
#include <gtest/gtest.h>

#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>

#include "calib/frame_csv.h"
#include "cli_runner.h"
#include "expect_error.h"
#include "model/mesh.h"
#include "scratch_dir.h"
#include "shapes/goal_importer.h"
#include "shapes/resample.h"

namespace hj {
namespace {

using testing_support::quoted;
using testing_support::read_text;
using testing_support::run_cli;
using testing_support::ScratchDir;

const ArrayGeometry kSmall{2, 3, 0.038, 2};  // 5 x 7 points

// A goal image whose row 0 is the top: value 10 r + c - 20 (negative at the top).
HeightMap table(long rows, long cols) {
  HeightMap map;
  map.z.resize(rows, cols);
  for (long r = 0; r < rows; ++r)
    for (long c = 0; c < cols; ++c) map.z(r, c) = 10.0 * r + c - 20.0;
  map.source = "table";
  return map;
}

TEST(AbsoluteHeights, ATableOfTheMeshPointsIsTheGoalAtThemRowZeroAtTheTop) {
  const Mesh mesh(kSmall);
  const HeightMap goal = table(mesh.point_rows(), mesh.point_cols());
  const Eigen::MatrixXd mm = absolute_to_mesh(goal, mesh);
  ASSERT_EQ(mm.rows(), mesh.point_rows());
  for (int i = 0; i < mm.rows(); ++i)
    for (int j = 0; j < mm.cols(); ++j) EXPECT_DOUBLE_EQ(mm(i, j), goal.z(mesh.point_rows() - 1 - i, j));
  EXPECT_LT(mm.minCoeff(), 0.0);  // negative heights kept
}

TEST(AbsoluteHeights, AnotherSizeIsAveragedNotRescaled) {
  const Mesh mesh(kSmall);
  HeightMap flat;
  flat.z = Eigen::MatrixXd::Constant(40, 57, -3.5);
  flat.source = "flat";
  const Eigen::MatrixXd mm = absolute_to_mesh(flat, mesh);
  EXPECT_NEAR(mm.minCoeff(), -3.5, 1e-12);
  EXPECT_NEAR(mm.maxCoeff(), -3.5, 1e-12);
  // The scaled goal of the same image would be all zeros: relief 0.
  EXPECT_EQ(goal_to_mesh(flat, mesh, GoalHeights::kScaled, 0.0).maxCoeff(), 0.0);
  EXPECT_NEAR(goal_to_mesh(flat, mesh, GoalHeights::kAbsolute, 0.0).maxCoeff(), -3.5, 1e-12);
}

TEST(AbsoluteHeights, ANanAtAMeshPointIsNamed) {
  const Mesh mesh(kSmall);
  HeightMap goal = table(mesh.point_rows(), mesh.point_cols());
  goal.z(1, 2) = std::numeric_limits<double>::quiet_NaN();
  testing_support::expect_error<std::invalid_argument>([&] { absolute_to_mesh(goal, mesh); }, {"row 1, column 2 is NaN"});
}

TEST(AbsoluteHeights, FormatsWhoseValuesAreNotMillimetresAreRefused) {
  EXPECT_NO_THROW(check_absolute_goal_format("a/goal.CSV"));
  EXPECT_NO_THROW(check_absolute_goal_format("goal.tif"));
  testing_support::expect_error<std::invalid_argument>([] { check_absolute_goal_format("photo.png"); }, {"photo.png", "CSV or float TIFF"});
  testing_support::expect_error<std::invalid_argument>([] { parse_goal_heights("mm"); }, {"\"mm\"", "scaled"});
}

TEST(AbsoluteHeights, PlanTakesTheGoalAtFaceValue) {
  ScratchDir dir;
  const auto csv = dir.path / "goal.csv";
  std::ofstream(csv) << "4,5,6,5,4\n3,8,9,8,3\n0,1,2,1,0\n";
  const auto out = dir.path / "out";
  ASSERT_EQ(run_cli("plan " + quoted(csv) + " --rows 1 --cols 2 --segments 2 --heights absolute --out " + quoted(out),
                    dir.path),
            0)
      << read_text(dir.path / "stderr.txt");
  const Eigen::MatrixXd goal = read_frame_csv(out / "goal.csv", 3, 5);
  ASSERT_EQ(goal.rows(), 3);
  EXPECT_DOUBLE_EQ(goal(2, 2), 6.0);  // the file's top row is the mesh's last
  EXPECT_DOUBLE_EQ(goal(1, 2), 9.0);
  const auto plan = nlohmann::json::parse(read_text(out / "plan.json"));
  EXPECT_EQ(plan["heights"], "absolute");
  EXPECT_DOUBLE_EQ(plan["max_height_mm"].get<double>(), 9.0);

  EXPECT_EQ(run_cli("plan " + quoted(csv) + " --rows 1 --cols 2 --heights absolute --max-height-mm 5 --out " +
                        quoted(out),
                    dir.path),
            2);
  EXPECT_NE(read_text(dir.path / "stderr.txt").find("exclude each other"), std::string::npos);
}

}  // namespace
}  // namespace hj
