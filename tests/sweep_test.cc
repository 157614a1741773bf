// The sweep (src/plan/sweep.h): every goal at every size on a thread pool,
// failures and budget overruns recorded as rows, the Table 2 fit; and the
// `hapticjam sweep` command's files.
#include <gtest/gtest.h>

#include "expect_error.h"

#include <sys/wait.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "plan/sweep.h"
#include "scratch_dir.h"

namespace hj {
namespace {

namespace fs = std::filesystem;
using testing_support::expect_error;
using testing_support::ScratchDir;

SweepGoal bump_goal(const std::string& name, double width) {
  SweepGoal g{name, {}};
  g.map.z.resize(40, 40);
  for (int r = 0; r < 40; ++r)
    for (int c = 0; c < 40; ++c) g.map.z(r, c) = std::exp(-(std::pow(r - 19.5, 2) + std::pow(c - 19.5, 2)) / (width * width));
  g.map.source = name;
  return g;
}

TEST(Sweep, ParsesSizes) {
  // The paper's Table 1: 16 sizes, 1x2 (2 cells) to 9x12 (108 cells).
  const auto paper = parse_array_sizes("paper");
  ASSERT_EQ(paper.size(), 16u);
  EXPECT_EQ(paper.front().rows * paper.front().cols, 2);
  EXPECT_EQ(paper.back().rows, 9);
  EXPECT_EQ(paper.back().cols, 12);
  EXPECT_EQ(parse_array_sizes("quick").size(), 5u);
  EXPECT_EQ(table2_alphas().size(), 5u);
  EXPECT_DOUBLE_EQ(table2_alphas()[1], 0.125);
  EXPECT_EQ(paper_table2_r2(0.125), 0.7583);
  EXPECT_FALSE(paper_table2_r2(1.0 / 3.0));
  const auto two = parse_array_sizes("2x3,10X1");
  ASSERT_EQ(two.size(), 2u);
  EXPECT_EQ(two[0].cols, 3);
  EXPECT_EQ(two[1].rows, 10);
  expect_error<std::invalid_argument>([] { (void)parse_array_sizes("2x3,4"); }, {"\"4\"", "RxC"});
  expect_error<std::invalid_argument>([] { (void)parse_array_sizes("0x3"); }, {"1..100"});
}

TEST(Sweep, EveryGoalAtEverySizeInOrderOnTwoThreads) {
  SweepOptions o;
  o.sizes = {{2, 2}, {2, 3}};
  o.jobs = 2;
  const std::vector<SweepGoal> goals{bump_goal("narrow", 6.0), bump_goal("wide", 14.0)};
  int calls = 0;
  const auto rows = run_sweep(goals, o, [&](int done, int total, const SweepRow&) {
    ++calls;
    EXPECT_EQ(total, 4);
    EXPECT_EQ(done, calls);
  });
  EXPECT_EQ(calls, 4);
  ASSERT_EQ(rows.size(), 4u);
  EXPECT_EQ(rows[0].goal, "narrow");
  EXPECT_EQ(rows[1].cols, 3);
  EXPECT_EQ(rows[2].goal, "wide");
  for (const auto& r : rows) {
    SCOPED_TRACE(r.goal + " " + std::to_string(r.rows) + "x" + std::to_string(r.cols));
    EXPECT_EQ(r.status, "ok") << r.detail;
    ASSERT_TRUE(r.correlation);
    EXPECT_GT(*r.correlation, 0.5);
    ASSERT_EQ(r.laplace_mean.size(), table2_alphas().size());
    for (double l : r.laplace_mean) EXPECT_TRUE(l >= 0.0 && l <= 1.0);
    EXPECT_GT(r.steps, 0);
  }
  const auto t2 = table2(rows, o.alphas);
  ASSERT_EQ(t2.size(), o.alphas.size());
  for (const auto& t : t2) {
    ASSERT_TRUE(t.fit);
    EXPECT_EQ(t.fit->n, 4);
  }
}

TEST(Sweep, OverBudgetAndFailedPlansAreRowsNotExceptions) {
  SweepOptions o;
  o.sizes = {{2, 2}};
  o.budget_s = 1e-9;
  const auto over = run_sweep({bump_goal("bump", 8.0)}, o);
  ASSERT_EQ(over.size(), 1u);
  EXPECT_EQ(over[0].status, "over-budget");
  EXPECT_FALSE(over[0].correlation);
  EXPECT_NE(over[0].detail.find("budget"), std::string::npos);

  SweepGoal flat{"flat", {}};
  flat.map.z = Eigen::MatrixXd::Constant(5, 5, 2.0);
  o.budget_s = 60;
  const auto undefined = run_sweep({flat}, o);
  EXPECT_EQ(undefined[0].status, "undefined");
  EXPECT_FALSE(undefined[0].detail.empty());

  SweepGoal empty{"empty", {}};
  const auto failed = run_sweep({empty}, o);
  EXPECT_EQ(failed[0].status, "failed");
  EXPECT_FALSE(failed[0].detail.empty());

  o.planner = "no-such-planner";
  expect_error<std::invalid_argument>([&] { (void)run_sweep({flat}, o); }, {"no-such-planner"});
}

std::string read_text(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(SweepCli, WritesTheTableTheFitAndBothFigures) {
  const ScratchDir dir("cli");
  {
    std::ofstream csv(dir.path / "bump.csv");
    for (int r = 0; r < 20; ++r)
      for (int c = 0; c < 20; ++c) csv << std::exp(-(std::pow(r - 9.5, 2) + std::pow(c - 9.5, 2)) / 30.0) << (c < 19 ? "," : "\n");
  }
  const fs::path out = dir.path / "out";
  const std::string command = std::string("'") + HJ_CLI_PATH + "' sweep '" + (dir.path / "bump.csv").string() +
                              "' --sizes 2x2,2x3 --jobs 2 --out '" + out.string() + "' >'" +
                              (dir.path / "stdout.txt").string() + "' 2>'" + (dir.path / "stderr.txt").string() + "'";
  const int status = std::system(command.c_str());
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << read_text(dir.path / "stderr.txt");
  const std::string table = read_text(out / "sweep.csv");
  EXPECT_EQ(table.substr(0, table.find('\n')),
            "goal,rows,cols,cells,correlation,laplace_mean_a0,laplace_mean_a1_8,laplace_mean_a1_4,laplace_mean_a1_2,"
            "laplace_mean_a1,steps,refused,relief_mm,seconds,settle_seconds,refused_seconds,status,detail,note");
  EXPECT_NE(table.find("bump,2,3,6,"), std::string::npos);
  // Each row's time splits into the settles kept and refused, within its whole.
  std::istringstream rows(table.substr(table.find('\n') + 1));
  for (std::string row; std::getline(rows, row);) {
    std::vector<std::string> cells;
    std::istringstream fields(row);
    for (std::string cell; std::getline(fields, cell, ',');) cells.push_back(cell);
    ASSERT_GE(cells.size(), 16u) << row;
    const double seconds = std::stod(cells[13]), kept = std::stod(cells[14]), refused = std::stod(cells[15]);
    EXPECT_GT(kept, 0.0) << row;
    EXPECT_GE(refused, 0.0) << row;
    EXPECT_LE(kept + refused, seconds) << row;
  }
  const std::string t2 = read_text(out / "table2.csv");
  EXPECT_EQ(t2.substr(0, t2.find('\n')), "alpha_l,slope,intercept,r2,n,paper_r2");
  EXPECT_NE(t2.find("0.7583"), std::string::npos);  // the paper's r^2 at alpha_L = 1/8
  EXPECT_TRUE(fs::file_size(out / "fig11_correlation_vs_cells.png") > 1000);
  EXPECT_TRUE(fs::file_size(out / "fig13_correlation_vs_laplace.png") > 1000);
  EXPECT_NE(read_text(dir.path / "stdout.txt").find("Table 2 analogue"), std::string::npos);
}

}  // namespace
}  // namespace hj
