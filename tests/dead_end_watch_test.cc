// The planner's dead-end watch (sim/dead_end_watch.h): a fold past the
// refusal angle ends a flow at once; a folded mesh that has stopped moving,
// or crawls, and whose residual has stopped falling ends it after the stall
// limit, as does a flow that comes back to a state it passed; an unfolded
// mesh, a moving one, or a residual that keeps falling, never does.
#include "sim/dead_end_watch.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <utility>

#include "sim/mesh_folds.h"
#include "sim/simulator.h"

namespace hj {
namespace {

// A 2 x 2 mesh (p = 4) whose point (3, 5) is turned back 130 degrees from
// +x about point (3, 4): folded past 120 degrees, not past 150 anywhere.
Eigen::Matrix3Xd folded_between_the_limits(const Mesh& mesh) {
  Eigen::Matrix3Xd x = mesh.rest_positions();
  const double h = mesh.spacing(), turn = 130.0 * M_PI / 180.0;
  x.col(mesh.index(3, 5)) = x.col(mesh.index(3, 4)) + h * Eigen::Vector3d(std::cos(turn), 0.0, std::sin(turn));
  return x;
}

constexpr DeadEndWatchOptions kOptions{150.0, 120.0, 20};

// Feeds the watch flow(step) = (positions, residual) step by step and
// expects "stalled on a folded mesh" at exactly the stall limit.
template <typename Flow>
void expect_stalled_after_the_limit(const Mesh& mesh, Flow flow) {
  DeadEndWatch watch(mesh, kOptions);
  int step = 0;
  for (;; ++step) {
    const auto [x, residual_n] = flow(step);
    if (watch.dead_end(x, residual_n)) break;
    ASSERT_LT(step, kOptions.stall_steps) << "not a dead end after " << step + 1 << " steps";
  }
  EXPECT_EQ(step, kOptions.stall_steps);
  EXPECT_EQ(std::string(watch.reason()), "stalled on a folded mesh");
}

// `base` lifted by `per_step` mesh spacings a step: a surface on its way.
Eigen::Matrix3Xd lifted(const Mesh& mesh, const Eigen::Matrix3Xd& base, int step, double per_step) {
  return base.colwise() + Eigen::Vector3d(0.0, 0.0, per_step * step * mesh.spacing());
}

// Feeds the watch positions(step) for 200 steps, the residual never
// falling, and expects no dead end.
template <typename Positions>
void expect_never_a_dead_end(const Mesh& mesh, Positions positions) {
  DeadEndWatch watch(mesh, kOptions);
  for (int step = 0; step < 200; ++step) EXPECT_FALSE(watch.dead_end(positions(step), 1.0)) << step;
}

TEST(DeadEndWatch, AnUnfoldedMeshIsNeverADeadEndHoweverTheResidualStalls) {
  const Mesh mesh(ArrayGeometry{2, 2, 0.038, 4});
  DeadEndWatch watch(mesh, kOptions);
  for (int step = 0; step < 200; ++step) EXPECT_FALSE(watch.dead_end(mesh.rest_positions(), 0.01)) << step;
}

TEST(DeadEndWatch, AFoldPastTheRefusalAngleIsADeadEndAtOnce) {
  const Mesh mesh(ArrayGeometry{2, 2, 0.038, 4});
  Eigen::Matrix3Xd x = mesh.rest_positions();
  x(0, mesh.index(3, 4)) -= 1.5 * mesh.spacing();  // turned back by 180 degrees
  DeadEndWatch watch(mesh, kOptions);
  EXPECT_TRUE(watch.dead_end(x, 1.0));
  EXPECT_EQ(std::string(watch.reason()), "folded past the refusal angle");
}

TEST(DeadEndWatch, AFoldedMeshThatStandsStillAndStopsFallingIsADeadEndAfterTheStallLimit) {
  const Mesh mesh(ArrayGeometry{2, 2, 0.038, 4});
  const Eigen::Matrix3Xd x = folded_between_the_limits(mesh);
  const double sharpest = find_mesh_folds(mesh, x).sharpest_deg;
  ASSERT_GT(sharpest, kOptions.stall_fold_deg);
  ASSERT_LT(sharpest, kOptions.refuse_fold_deg);
  // The mesh stands still; the residual wanders (0.6 to 1.4 x its first
  // value) but never halves.
  expect_stalled_after_the_limit(mesh, [&](int step) { return std::make_pair(x, 1.0 + 0.4 * std::sin(step)); });
}

// A snap-through passes folded states with a residual that does not fall,
// but the surface is on its way: here it moves 0.05 h a step, 1 h in 20.
TEST(DeadEndWatch, AFoldedMeshThatKeepsMovingIsNoDeadEndHoweverTheResidualStalls) {
  const Mesh mesh(ArrayGeometry{2, 2, 0.038, 4});
  const Eigen::Matrix3Xd x = folded_between_the_limits(mesh);
  expect_never_a_dead_end(mesh, [&](int step) { return lifted(mesh, x, step, 0.05); });
}

// A flow that stays folded and crawls, 0.02 h a step (0.4 h in 20), its
// residual not falling, goes nowhere either (the bunny and Luxembourg 9 x 12
// sags crawl 0.6-0.7 h in 20 steps before they stand still or come back).
TEST(DeadEndWatch, AFoldedMeshThatCrawlsIsADeadEndAfterTheStallLimit) {
  const Mesh mesh(ArrayGeometry{2, 2, 0.038, 4});
  const Eigen::Matrix3Xd x = folded_between_the_limits(mesh);
  expect_stalled_after_the_limit(mesh, [&](int step) { return std::make_pair(lifted(mesh, x, step, 0.02), 1.0); });
}

// A crawl that unfolds once in the window may be on its way out of the fold.
TEST(DeadEndWatch, ACrawlThatUnfoldedWithinTheStallLimitIsNoDeadEnd) {
  const Mesh mesh(ArrayGeometry{2, 2, 0.038, 4});
  const Eigen::Matrix3Xd folded = folded_between_the_limits(mesh);
  // Unfolded every 15th step, each time somewhere new.
  expect_never_a_dead_end(mesh, [&](int step) {
    return lifted(mesh, step % 15 == 14 ? Eigen::Matrix3Xd(mesh.rest_positions()) : folded, step, 0.02);
  });
}

TEST(DeadEndWatch, AFoldedMeshWhoseResidualKeepsFallingIsNoDeadEnd) {
  const Mesh mesh(ArrayGeometry{2, 2, 0.038, 4});
  const Eigen::Matrix3Xd x = folded_between_the_limits(mesh);
  DeadEndWatch watch(mesh, kOptions);
  // Halving every 10 steps, slower than every step but within the limit.
  for (int step = 0; step < 200; ++step)
    EXPECT_FALSE(watch.dead_end(x, std::pow(0.5, step / 10.0))) << step;
}

// A cycle: folds come and go, and the flow keeps coming back to where it
// was (the Luxembourg 9 x 12 sag, period about 40 steps).
TEST(DeadEndWatch, AFlowThatComesBackToAFoldedStateItPassedIsADeadEndThoughItUnfoldedBetween) {
  const Mesh mesh(ArrayGeometry{2, 2, 0.038, 4});
  const Eigen::Matrix3Xd folded = folded_between_the_limits(mesh);
  DeadEndWatch watch(mesh, kOptions);
  const int half_period = kOptions.stall_steps / 2 + 1;
  int step = 0;
  for (; step < 10 * half_period; ++step) {
    const bool away = (step / half_period) % 2 == 1;
    const Eigen::Matrix3Xd x = away ? Eigen::Matrix3Xd(mesh.rest_positions()) : folded;
    if (watch.dead_end(x, 1.0)) break;
  }
  EXPECT_EQ(step, 2 * half_period) << "the first return to the folded state";
  EXPECT_EQ(std::string(watch.reason()), "stalled on a folded mesh");
}

// A snap-through that unfolds on its way never comes back.
TEST(DeadEndWatch, AFlowThatFoldsUnfoldsAndMovesOnIsNoDeadEnd) {
  const Mesh mesh(ArrayGeometry{2, 2, 0.038, 4});
  const Eigen::Matrix3Xd folded = folded_between_the_limits(mesh);
  expect_never_a_dead_end(mesh, [&](int step) {
    return lifted(mesh, step % 7 == 6 ? Eigen::Matrix3Xd(mesh.rest_positions()) : folded, step, 0.05);
  });
}

TEST(DeadEndWatch, ZeroStallStepsTurnTheStallLimitOff) {
  const Mesh mesh(ArrayGeometry{2, 2, 0.038, 4});
  DeadEndWatch watch(mesh, DeadEndWatchOptions{150.0, 120.0, 0});
  for (int step = 0; step < 200; ++step) EXPECT_FALSE(watch.dead_end(folded_between_the_limits(mesh), 1.0));
}

TEST(DeadEndWatch, TheSimulatorNamesABadStallOption) {
  const ArrayGeometry g{1, 2, 0.038, 4};
  SimulatorOptions options;
  options.stall_fold_deg = 160.0;  // above refuse_fold_deg
  try {
    Simulator sim(g, SurfaceParameters::paper_defaults(g), options);
    FAIL() << "accepted stall_fold_deg above refuse_fold_deg";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("stall_fold_deg"), std::string::npos) << e.what();
  }
  options = {};
  options.refuse_stall_steps = -1;
  EXPECT_THROW(Simulator(g, SurfaceParameters::paper_defaults(g), options), std::invalid_argument);
}

}  // namespace
}  // namespace hj
