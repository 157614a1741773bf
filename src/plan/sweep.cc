#include "plan/sweep.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <mutex>
#include <numeric>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "metrics/correlation.h"
#include "model/mesh.h"
#include "plan/planner.h"
#include "shapes/resample.h"
#include "sim/surface_measures.h"

namespace hj {

std::vector<ArraySize> paper_array_sizes() {
  return {{1, 2}, {2, 3}, {3, 4}, {3, 5}, {4, 5}, {4, 6}, {5, 6},  {5, 7},
          {5, 8}, {6, 7}, {6, 8}, {6, 9}, {7, 9}, {7, 10}, {8, 11}, {9, 12}};
}

std::vector<ArraySize> quick_array_sizes() { return {{2, 2}, {3, 4}, {4, 6}, {6, 8}, {9, 12}}; }

std::vector<double> table2_alphas() { return {0.0, 1.0 / 8.0, 1.0 / 4.0, 0.5, 1.0}; }

std::optional<double> paper_table2_r2(double alpha) {
  const std::vector<double> r2 = {0.7555, 0.7583, 0.7545, 0.7412, 0.7293};
  const std::vector<double> alphas = table2_alphas();
  for (std::size_t k = 0; k < alphas.size(); ++k)
    if (std::abs(alpha - alphas[k]) < 1e-12) return r2[k];
  return std::nullopt;
}

std::vector<ArraySize> parse_array_sizes(const std::string& text) {
  if (text == "paper") return paper_array_sizes();
  if (text == "quick") return quick_array_sizes();
  std::vector<ArraySize> out;
  std::istringstream in(text);
  for (std::string item; std::getline(in, item, ',');) {
    const auto x = item.find_first_of("xX");
    int r = 0, c = 0;
    try {
      std::size_t used_r = 0, used_c = 0;
      if (x == std::string::npos) throw std::invalid_argument("no x");
      r = std::stoi(item.substr(0, x), &used_r);
      c = std::stoi(item.substr(x + 1), &used_c);
      if (used_r != x || used_c != item.size() - x - 1) throw std::invalid_argument("trailing");
    } catch (const std::exception&) {
      throw std::invalid_argument("array sizes \"" + text + "\": \"" + item + "\" is not RxC (e.g. 3x4), or use \"paper\"");
    }
    if (r < 1 || c < 1 || r > 100 || c > 100)
      throw std::invalid_argument("array sizes \"" + text + "\": \"" + item + "\" must have 1..100 rows and columns");
    out.push_back({r, c});
  }
  if (out.empty()) throw std::invalid_argument("array sizes \"" + text + "\": no size given");
  return out;
}

void SweepOptions::validate() const {
  if (sizes.empty()) throw std::invalid_argument("SweepOptions.sizes must not be empty");
  if (segments < 2) throw std::invalid_argument("SweepOptions.segments must be >= 2");
  if (!(max_height_mm >= 0.0) || !std::isfinite(max_height_mm))
    throw std::invalid_argument("SweepOptions.max_height_mm must be a positive number of mm (0: the array's default)");
  if (jobs < 0) throw std::invalid_argument("SweepOptions.jobs must be >= 0 (0: one per core)");
  if (!(budget_s > 0.0)) throw std::invalid_argument("SweepOptions.budget_s must be a positive number of seconds");
  for (double a : alphas)
    if (!(a >= 0.0 && a <= 1.0)) throw std::invalid_argument("SweepOptions.alphas must lie in [0, 1]");
  (void)make_planner(planner);  // names the known planners if unknown
  if (align) align->validate();
}

namespace {

SweepRow run_one(const SweepGoal& goal, ArraySize size, const SweepOptions& options) {
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  SweepRow row;
  row.goal = goal.name;
  row.rows = size.rows;
  row.cols = size.cols;
  const auto elapsed = [&] { return std::chrono::duration<double>(Clock::now() - start).count(); };
  try {
    const ArrayGeometry geometry{size.rows, size.cols, 0.038, options.segments};
    const Mesh mesh(geometry);
    row.relief_mm = relief_or_default_mm(options.max_height_mm, geometry);
    PlanRequest request{geometry, SurfaceParameters::paper_defaults(geometry), {}, {}, goal.map.z};
    PlanCallbacks callbacks;
    // Aligned, a row plans up to 1 + plans goals one after the other, each within the budget.
    const double budget_s = options.budget_s * (options.align ? 1 + options.align->plans : 1);
    callbacks.cancelled = [&] { return elapsed() > budget_s; };
    PlanResult result;
    const HeightMap* scored_goal = &goal.map;
    std::optional<AlignedPlan> aligned;
    if (options.align) {
      AlignedPlanOptions align = *options.align;
      align.threads = 1;  // the sweep's pool is busy already
      const Region whole{0.0, 0.0, double(goal.map.z.cols()), double(goal.map.z.rows()), false};
      aligned = plan_aligned(options.planner, goal.map, whole, request, row.relief_mm, align, callbacks);
      request.goal_mm = aligned->chosen.goal_mm;
      for (double a : options.alphas) row.laplace_mean.push_back(laplace_mean(request.goal_mm, a));
      scored_goal = &aligned->goal;
      result = std::move(aligned->result);
      row.align = SweepAlignment{aligned->chosen.transform,
                                 std::isfinite(aligned->unaligned_score) ? std::optional(aligned->unaligned_score)
                                                                         : std::nullopt,
                                 aligned->planned.front().seconds, int(aligned->planned.size())};
    } else {
      request.goal_mm = resample_to_mesh(goal.map, mesh, row.relief_mm);
      for (double a : options.alphas) row.laplace_mean.push_back(laplace_mean(request.goal_mm, a));
      result = make_planner(options.planner)->plan(request, callbacks);
    }
    row.steps = int(result.steps.size());
    row.refused = int(result.refused.size());
    row.settle_seconds = result.settle_seconds;
    row.refused_seconds = result.refused_seconds;
    row.note = result.note;
    // Mesh rows run along +y; the goal image's row 0 is its top.
    const Eigen::MatrixXd predicted_image = (point_heights(mesh, result.final_state.x) * 1000.0).colwise().reverse();
    const Correlation corr = correlate_with_goal(scored_goal->z, predicted_image);
    row.correlation = corr.value;
    row.status = corr.value ? "ok" : "undefined";
    row.detail = corr.undefined_reason;
  } catch (const PlanCancelled&) {
    row.status = "over-budget";
    std::ostringstream s;
    s << "stopped after " << elapsed() << " s (budget " << options.budget_s << " s a plan)";
    row.detail = s.str();
  } catch (const std::exception& e) {
    row.status = "failed";
    row.detail = e.what();
  }
  row.seconds = elapsed();
  return row;
}

}  // namespace

std::vector<SweepRow> run_sweep(const std::vector<SweepGoal>& goals, const SweepOptions& options,
                                const std::function<void(int, int, const SweepRow&)>& progress) {
  options.validate();
  struct Task {
    std::size_t goal, size;
  };
  std::vector<Task> tasks;
  for (std::size_t g = 0; g < goals.size(); ++g)
    for (std::size_t s = 0; s < options.sizes.size(); ++s) tasks.push_back({g, s});
  std::vector<SweepRow> rows(tasks.size());
  // Largest arrays first, so a slow one does not start last and leave the other cores idle.
  std::vector<std::size_t> order(tasks.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    const auto& sa = options.sizes[tasks[a].size];
    const auto& sb = options.sizes[tasks[b].size];
    return sa.rows * sa.cols > sb.rows * sb.cols;
  });

  std::atomic<std::size_t> next{0};
  std::mutex mutex;
  int done = 0;
  const auto worker = [&] {
    for (std::size_t k; (k = next.fetch_add(1)) < order.size();) {
      const Task& t = tasks[order[k]];
      SweepRow row = run_one(goals[t.goal], options.sizes[t.size], options);
      const std::lock_guard<std::mutex> lock(mutex);
      rows[order[k]] = std::move(row);
      ++done;
      if (progress) progress(done, int(tasks.size()), rows[order[k]]);
    }
  };
  const int jobs = std::max(1, std::min<int>(options.jobs > 0 ? options.jobs : int(std::thread::hardware_concurrency()),
                                             int(tasks.size())));
  std::vector<std::thread> pool;
  for (int j = 1; j < jobs; ++j) pool.emplace_back(worker);
  worker();
  for (auto& t : pool) t.join();
  return rows;
}

std::vector<Table2Row> table2(const std::vector<SweepRow>& rows, const std::vector<double>& alphas) {
  std::vector<Table2Row> out;
  for (std::size_t a = 0; a < alphas.size(); ++a) {
    std::vector<double> x, y;
    for (const auto& r : rows)
      if (r.correlation && a < r.laplace_mean.size()) {
        x.push_back(r.laplace_mean[a]);
        y.push_back(*r.correlation);
      }
    Table2Row t{alphas[a], std::nullopt};
    try {
      t.fit = fit_line(x, y);
    } catch (const std::invalid_argument&) {
    }
    out.push_back(t);
  }
  return out;
}

}  // namespace hj
