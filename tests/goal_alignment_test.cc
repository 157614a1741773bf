// Aligning a goal's window so its valleys fall on nodes (shapes/goal_alignment.h,
// plan/aligned_plan.h): a valley mid-cell is moved onto a node, one already on
// a node is left where it is, the transforms stay in their bounds and inside
// the source, bad options are named, and the aligned plan is never worse.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>

#include "cli_runner.h"
#include "expect_error.h"
#include "plan/aligned_plan.h"
#include "plan/sweep.h"
#include "scratch_dir.h"
#include "shapes/goal_alignment.h"

namespace hj {
namespace {

using testing_support::expect_error;

const ArrayGeometry kPaper{3, 4, 0.038, 4};
constexpr double kPixelsPerCell = 40.0;
constexpr double kReliefMm = 30.0;
// The unaligned window: 4 x 3 cells of 40 px in the middle of a 320 x 240 source.
const Region kWindow{80.0, 60.0, 240.0, 180.0, false};

// Source pixel coordinates (u along columns, v along rows, pixel q spanning
// [q, q + 1]) of a point of the unaligned window, in cells from its bottom-left.
double u_of(double x_cells) { return kWindow.x0 + x_cells * kPixelsPerCell; }
double v_of(double y_cells) { return kWindow.y1 - y_cells * kPixelsPerCell; }

// A plateau with one round valley at (u0, v0), 0.3 cells wide (sd).
HeightMap plateau_with_valley(double u0, double v0) {
  HeightMap map;
  map.source = "valley";
  map.z.resize(240, 320);
  const double sd = 0.3 * kPixelsPerCell;
  for (long r = 0; r < map.z.rows(); ++r)
    for (long c = 0; c < map.z.cols(); ++c) {
      const double du = c + 0.5 - u0, dv = r + 0.5 - v0;
      map.z(r, c) = 100.0 - 50.0 * std::exp(-(du * du + dv * dv) / (2.0 * sd * sd));
    }
  return map;
}

// Where source point (u, v) lands on the array through `window`, in cells.
Eigen::Vector2d on_array(const Region& window, double u, double v) {
  return {(u - window.x0) / (window.x1 - window.x0) * kPaper.cols,
          (window.y1 - v) / (window.y1 - window.y0) * kPaper.rows};
}

// Distance in cells to the nearest interior node (cell corner off the boundary).
double node_distance(const Eigen::Vector2d& p) {
  const double b = std::clamp(std::round(p.x()), 1.0, kPaper.cols - 1.0);
  const double a = std::clamp(std::round(p.y()), 1.0, kPaper.rows - 1.0);
  return std::hypot(p.x() - b, p.y() - a);
}

TEST(GoalAlignment, AValleyMidCellIsMovedOntoANode) {
  const double u0 = u_of(1.5), v0 = v_of(1.5);  // the middle of cell (1, 1)
  const HeightMap source = plateau_with_valley(u0, v0);
  const auto candidates = alignment_candidates(source, kWindow, Mesh(kPaper), kReliefMm, {});
  ASSERT_GE(candidates.size(), 2u);

  const AlignmentCandidate& identity = candidates.front();
  EXPECT_TRUE(identity.transform.is_identity());
  EXPECT_EQ(identity.valleys, 1);
  EXPECT_NEAR(node_distance(on_array(identity.window, u0, v0)), std::sqrt(0.5), 0.01);

  // The best by the criterion puts the valley on a node, as the geometry of its window says.
  const AlignmentCandidate& best = candidates[1];
  EXPECT_LT(node_distance(on_array(best.window, u0, v0)), 0.1);
  EXPECT_LT(best.valley_cost, 0.2 * identity.valley_cost);
  const auto valleys = goal_valleys(best.goal_mm, kPaper.segments);
  ASSERT_EQ(valleys.size(), 1u);
  EXPECT_LT(valleys[0].node_distance_cells, 0.1);
}

TEST(GoalAlignment, ValleysOnNodesKeepTheIdentity) {
  const HeightMap source = plateau_with_valley(u_of(2.0), v_of(1.0));  // on node (1, 2)
  const auto candidates = alignment_candidates(source, kWindow, Mesh(kPaper), kReliefMm, {});
  ASSERT_FALSE(candidates.empty());
  EXPECT_NEAR(candidates.front().valley_cost, 0.0, 1e-6);
  for (const auto& c : candidates) EXPECT_GE(c.valley_cost, candidates.front().valley_cost - 1e-9);

  const SurfaceParameters params = SurfaceParameters::paper_defaults(kPaper);
  const AlignedPlan plan = plan_aligned("algorithm2", source, kWindow, {kPaper, params, {}, {}, {}}, kReliefMm, {});
  EXPECT_TRUE(plan.chosen.transform.is_identity());
  EXPECT_EQ(plan.planned.size(), 1u);  // nothing closer to the nodes, so nothing else planned
  EXPECT_DOUBLE_EQ(plan.gain(), 0.0);
}

TEST(GoalAlignment, TransformsStayWithinTheirBoundsAndTheSource) {
  const HeightMap source = plateau_with_valley(u_of(1.3), v_of(1.6));
  for (const AlignOptions& options : {AlignOptions{}, AlignOptions{0.25, 0.9, 0.95, 2, 2}}) {
    const auto candidates = alignment_candidates(source, kWindow, Mesh(kPaper), kReliefMm, options);
    EXPECT_GT(candidates.size(), 10u);
    for (const auto& c : candidates) {
      if (c.transform.is_identity()) continue;
      EXPECT_LE(std::abs(c.transform.shift_x_cells), options.max_shift_cells + 1e-12);
      EXPECT_LE(std::abs(c.transform.shift_y_cells), options.max_shift_cells + 1e-12);
      EXPECT_GE(c.transform.scale, options.min_scale - 1e-12);
      EXPECT_LE(c.transform.scale, options.max_scale + 1e-12);
      EXPECT_GE(c.window.x0, 0.0);
      EXPECT_GE(c.window.y0, 0.0);
      EXPECT_LE(c.window.x1, double(source.z.cols()));
      EXPECT_LE(c.window.y1, double(source.z.rows()));
      // Whole pixels, within a pixel of the scaled side.
      EXPECT_NEAR(c.window.x1 - c.window.x0, c.transform.scale * (kWindow.x1 - kWindow.x0), 1.0);
      EXPECT_NEAR(c.window.y1 - c.window.y0, c.transform.scale * (kWindow.y1 - kWindow.y0), 1.0);
      EXPECT_EQ(c.goal_mm.rows(), Mesh(kPaper).point_rows());
      EXPECT_NEAR(c.goal_mm.maxCoeff() - c.goal_mm.minCoeff(), kReliefMm, 1e-9);
    }
  }
  // A window that is the whole source leaves no room at full scale: every other window is smaller.
  const Region whole{0.0, 0.0, 320.0, 240.0, false};
  for (const auto& c : alignment_candidates(source, whole, Mesh(kPaper), kReliefMm, {})) {
    if (!c.transform.is_identity()) {
      EXPECT_LT(c.transform.scale, 1.0);
    }
  }
}

TEST(GoalAlignment, BadOptionsNameTheField) {
  const auto check = [](AlignOptions o, const std::string& field) {
    expect_error<std::invalid_argument>([&] { o.validate(); }, {field});
  };
  const double nan = std::numeric_limits<double>::quiet_NaN();
  check({nan, 0.8, 1.0, 4, 4}, "AlignOptions.max_shift_cells");
  check({0.6, 0.8, 1.0, 4, 4}, "AlignOptions.max_shift_cells");
  check({0.5, nan, 1.0, 4, 4}, "AlignOptions.min_scale");
  check({0.5, 0.0, 1.0, 4, 4}, "AlignOptions.min_scale");
  check({0.5, 0.8, 1.2, 4, 4}, "AlignOptions.max_scale");
  check({0.5, 0.9, 0.8, 4, 4}, "AlignOptions.max_scale");
  check({0.5, 0.8, 1.0, 0, 4}, "AlignOptions.shift_steps");
  check({0.5, 0.8, 1.0, 4, 0}, "AlignOptions.scale_steps");
  AlignedPlanOptions plans;
  plans.plans = -1;
  expect_error<std::invalid_argument>([&] { plans.validate(); }, {"AlignedPlanOptions.plans"});
  plans = {};
  plans.max_time_ratio = 0.5;
  expect_error<std::invalid_argument>([&] { plans.validate(); }, {"AlignedPlanOptions.max_time_ratio"});

  const HeightMap source = plateau_with_valley(u_of(1.5), v_of(1.5));
  const Mesh mesh(kPaper);
  expect_error<std::invalid_argument>(
      [&] { alignment_candidates(source, Region{0.0, 0.0, 400.0, 240.0, false}, mesh, kReliefMm, {}); },
      {"alignment window", "inside"});
  expect_error<std::invalid_argument>([&] { alignment_candidates(source, kWindow, mesh, nan, {}); },
                                      {"max_height_mm"});
  const SurfaceParameters params = SurfaceParameters::paper_defaults(kPaper);
  expect_error<std::invalid_argument>(
      [&] { plan_aligned("no-such-planner", source, kWindow, {kPaper, params, {}, {}, {}}, kReliefMm, {}); },
      {"no-such-planner"});
}

TEST(GoalAlignment, TheAlignedPlanIsNeverWorseThanTheUnaligned) {
  const HeightMap source = plateau_with_valley(u_of(1.5), v_of(1.5));
  const SurfaceParameters params = SurfaceParameters::paper_defaults(kPaper);
  const AlignedPlan plan = plan_aligned("algorithm2", source, kWindow, {kPaper, params, {}, {}, {}}, kReliefMm, {});
  ASSERT_GE(plan.planned.size(), 2u);
  EXPECT_TRUE(plan.planned.front().transform.is_identity());
  EXPECT_DOUBLE_EQ(plan.unaligned_score, plan.planned.front().score);
  for (const auto& p : plan.planned) EXPECT_LE(p.score, plan.score);
  EXPECT_GE(plan.gain(), 0.0);
  // The random control plans as many windows whatever their cost, and is held to the same rule.
  AlignedPlanOptions control;
  control.pick = AlignedPlanOptions::Pick::kRandom;
  control.plans = 1;
  const AlignedPlan random = plan_aligned("algorithm2", source, kWindow, {kPaper, params, {}, {}, {}}, kReliefMm, control);
  ASSERT_EQ(random.planned.size(), 2u);
  EXPECT_GE(random.gain(), 0.0);
  // The goal kept is the chosen window, at the mesh points and as the image scored.
  EXPECT_EQ(plan.goal.z.cols(), long(plan.chosen.window.x1 - plan.chosen.window.x0));
  EXPECT_EQ(plan.goal.z.rows(), long(plan.chosen.window.y1 - plan.chosen.window.y0));
}

TEST(GoalAlignment, SweepReportsTheTransformAndTheUnalignedCorrelation) {
  SweepOptions options;
  options.sizes = {{3, 4}};
  options.jobs = 1;
  options.align = AlignedPlanOptions{};
  const auto rows = run_sweep({{"valley", plateau_with_valley(u_of(1.5), v_of(1.5))}}, options);
  ASSERT_EQ(rows.size(), 1u);
  ASSERT_EQ(rows[0].status, "ok") << rows[0].detail;
  ASSERT_TRUE(rows[0].align && rows[0].align->unaligned_correlation && rows[0].correlation);
  EXPECT_GE(*rows[0].correlation, *rows[0].align->unaligned_correlation);
  EXPECT_GE(rows[0].align->planned, 2);
}

TEST(GoalAlignment, PlanWritesTheTransformAndGainOfARegion) {
  using namespace testing_support;
  ScratchDir dir;
  const auto csv = dir.path / "valley.csv";
  {
    const HeightMap map = plateau_with_valley(u_of(1.5), v_of(1.5));
    std::ofstream out(csv);
    for (long r = 0; r < map.z.rows(); ++r)
      for (long c = 0; c < map.z.cols(); ++c) out << map.z(r, c) << (c + 1 < map.z.cols() ? "," : "\n");
  }
  const auto out = dir.path / "out";
  ASSERT_EQ(run_cli("plan " + quoted(csv) + " --rows 3 --cols 4 --region 80,60,240,180 --align --json --out " +
                        quoted(out),
                    dir.path),
            0)
      << read_text(dir.path / "stderr.txt");
  const auto plan = nlohmann::json::parse(read_text(out / "plan.json"));
  ASSERT_TRUE(plan.contains("align"));
  const auto& align = plan["align"];
  for (const char* key : {"shift_x_cells", "shift_y_cells", "scale", "window", "correlation", "unaligned_correlation",
                          "gain", "candidates", "planned"})
    EXPECT_TRUE(align.contains(key)) << key;
  EXPECT_GE(align["gain"].get<double>(), 0.0);
  EXPECT_DOUBLE_EQ(plan["correlation"].get<double>(), align["correlation"].get<double>());
  EXPECT_LE(std::abs(align["shift_x_cells"].get<double>()), 0.5);
  const auto summary = nlohmann::json::parse(read_text(dir.path / "stdout.txt"));
  EXPECT_DOUBLE_EQ(summary["align"]["gain"].get<double>(), align["gain"].get<double>());
}

TEST(GoalAlignment, PlanRefusesAlignWithAbsoluteHeights) {
  using namespace testing_support;
  ScratchDir dir;
  const auto csv = dir.path / "goal.csv";
  std::ofstream(csv) << "4,5,6,5,4\n3,8,9,8,3\n0,1,2,1,0\n";
  EXPECT_EQ(run_cli("plan " + quoted(csv) + " --rows 1 --cols 2 --segments 2 --heights absolute --align --out " +
                        quoted(dir.path / "out"),
                    dir.path),
            2);
  const std::string err = read_text(dir.path / "stderr.txt");
  EXPECT_NE(err.find("--align"), std::string::npos) << err;
  EXPECT_NE(err.find("--heights absolute"), std::string::npos) << err;
}

}  // namespace
}  // namespace hj
