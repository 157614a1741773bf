// Many goals at many array sizes (the seed paper's Table 1 and Figs. 11 and
// 13): every plan independent and single-threaded, run on a pool of threads,
// each scored by Eq. 12 and by the Laplace predictor for every alpha_L of
// Table 2, then the Table-2-style line fit of correlation against it.
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "metrics/laplace_predictor.h"
#include "plan/aligned_plan.h"
#include "plan/default_planner.h"
#include "shapes/height_map.h"

namespace hj {

struct ArraySize {
  int rows = 0, cols = 0;
};

// The 16 array sizes of the paper's Table 1, 1x2 to 9x12 (2 to 108 cells).
std::vector<ArraySize> paper_array_sizes();
// Five sizes from 2x2 to 9x12 (2x2, 3x4, 4x6, 6x8, 9x12), for a quick look.
std::vector<ArraySize> quick_array_sizes();
// The alpha_L values of the paper's Table 2: 0, 1/8, 1/4, 1/2, 1.
std::vector<double> table2_alphas();
// The paper's Table 2 r^2 at alpha (0.7555 .. 0.7293), or empty for another alpha.
std::optional<double> paper_table2_r2(double alpha);
// "paper", "quick" or "RxC,RxC,..." (1..100 each). std::invalid_argument naming the text.
std::vector<ArraySize> parse_array_sizes(const std::string& text);

struct SweepGoal {
  std::string name;  // for tables and plots, e.g. the file stem
  HeightMap map;
};

struct SweepOptions {
  std::vector<ArraySize> sizes = paper_array_sizes();
  std::string planner = kDefaultPlanner;
  int segments = 4;
  double max_height_mm = 0.0;  // goal relief, mm; 0: each array's default_relief_mm
  int jobs = 0;            // threads; 0 = std::thread::hardware_concurrency()
  double budget_s = 120.0;  // per plan; checked between actions (a settle in progress is not interrupted)
  std::vector<double> alphas = table2_alphas();
  // Set: every goal planned aligned (plan_aligned, its plans one after the
  // other in the sweep's thread; a row's budget is then budget_s times the
  // number of goals it may plan, 1 + plans).
  std::optional<AlignedPlanOptions> align;
  // Throws std::invalid_argument naming the bad field.
  void validate() const;
};

// What alignment chose for a row (SweepOptions::align).
struct SweepAlignment {
  GoalTransform transform;
  std::optional<double> unaligned_correlation;
  double unaligned_seconds = 0.0;  // the unaligned goal's plan alone
  int planned = 0;                 // goals planned, the unaligned one included
};

struct SweepRow {
  std::string goal;
  int rows = 0, cols = 0;
  std::optional<double> correlation;  // Eq. 12; empty when undefined or the plan did not finish
  std::vector<double> laplace_mean;   // one per SweepOptions::alphas, of the goal as resampled to the mesh
  int steps = 0;
  int refused = 0;         // actions the planner refused as dead ends (PlanResult::refused)
  double relief_mm = 0.0;  // the goal's relief on this array
  double seconds = 0.0;
  // Of seconds: the settles the plan kept and those it refused as dead ends
  // (PlanResult::settle_seconds, refused_seconds).
  double settle_seconds = 0.0, refused_seconds = 0.0;
  std::string note;    // the planner's own account (PlanResult::note), e.g. a portfolio's choice
  std::string status;  // "ok", "undefined" (correlation undefined), "over-budget", "failed"
  std::string detail;  // the error or the reason the correlation is undefined
  std::optional<SweepAlignment> align;  // with SweepOptions::align; correlation is then the aligned goal's
  int cells() const { return rows * cols; }
};

// Runs every goal at every size. Rows come back goal-major in the order of
// `goals` and `options.sizes`; a plan that throws or runs over its budget is
// a row with that status, never an exception. progress(done, total, row) is
// called (serialised) as each plan ends.
// @throws std::invalid_argument on bad options or an unknown planner.
std::vector<SweepRow> run_sweep(const std::vector<SweepGoal>& goals, const SweepOptions& options,
                                const std::function<void(int done, int total, const SweepRow& row)>& progress = {});

struct Table2Row {
  double alpha = 0.0;
  std::optional<LinearFit> fit;  // empty when fewer than 2 usable rows or the Laplace mean does not vary
};

// For each alpha: the line fit of correlation against the Laplace mean over
// the rows with a correlation (status "ok").
std::vector<Table2Row> table2(const std::vector<SweepRow>& rows, const std::vector<double>& alphas);

}  // namespace hj
