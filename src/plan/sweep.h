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
#include "shapes/height_map.h"

namespace hj {

struct ArraySize {
  int rows = 0, cols = 0;
};

// The array sizes of the paper's Table 1 as we use them: 2x2, 3x4, 4x6, 6x8,
// 9x12. (The paper's own table was not available to us; these span its
// prototype, 3x4, to 9x12.)
std::vector<ArraySize> paper_array_sizes();
// The alpha_L values of the Table 2 analogue: 0, 1/6, 1/3 (Eq. 14), 1/2, 1.
std::vector<double> table2_alphas();
// "paper" or "RxC,RxC,..." (1..100 each). std::invalid_argument naming the text.
std::vector<ArraySize> parse_array_sizes(const std::string& text);

struct SweepGoal {
  std::string name;  // for tables and plots, e.g. the file stem
  HeightMap map;
};

struct SweepOptions {
  std::vector<ArraySize> sizes = paper_array_sizes();
  std::string planner = "algorithm2";
  int segments = 4;
  double max_height_mm = 30.0;
  int jobs = 0;            // threads; 0 = std::thread::hardware_concurrency()
  double budget_s = 120.0;  // per plan; checked between actions (a settle in progress is not interrupted)
  std::vector<double> alphas = table2_alphas();
  // Steps the static solver's explicit fallback may take in one settle
  // (SimulatorOptions::fallback_max_steps); a settle cannot be interrupted,
  // so this bounds how far a hard case overruns budget_s. 0: the simulator's
  // default (2,000,000). A settle that hits it fails the plan ("failed").
  long fallback_max_steps = 200'000;
  // Throws std::invalid_argument naming the bad field.
  void validate() const;
};

struct SweepRow {
  std::string goal;
  int rows = 0, cols = 0;
  std::optional<double> correlation;  // Eq. 12; empty when undefined or the plan did not finish
  std::vector<double> laplace_mean;   // one per SweepOptions::alphas, of the goal as resampled to the mesh
  int steps = 0;
  double seconds = 0.0;
  std::string status;  // "ok", "undefined" (correlation undefined), "over-budget", "failed"
  std::string detail;  // the error or the reason the correlation is undefined
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
