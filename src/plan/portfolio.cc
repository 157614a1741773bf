#include "plan/portfolio.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <thread>

#include "plan/algorithm2.h"
#include "plan/algorithm2_levelled.h"
#include "plan/from_above.h"

namespace hj {

namespace {

struct StrategyOutcome {
  std::optional<PlanResult> result;
  double score = -INFINITY;
  double seconds = 0.0;
  bool stopped_at_budget = false;  // result is the plan it had then
  bool not_started = false;        // the budget was spent before its turn
  std::string error;
};

using Clock = std::chrono::steady_clock;

// The time the strategies after Algorithm 2 may take: none until Algorithm 2
// has finished, then max_time_ratio times its time from the start, but never
// past max_seconds.
class StrategyBudget {
 public:
  StrategyBudget(const PortfolioOptions& options, Clock::time_point start) : options_(options), start_(start) {}
  void algorithm2_took(double seconds) {
    algorithm2_s_ = seconds;
    double limit = INFINITY;
    if (options_.max_time_ratio > 0.0) limit = std::max(options_.max_time_ratio * seconds, options_.min_budget_s);
    if (options_.max_seconds > 0.0) limit = std::min(limit, options_.max_seconds);
    limit_s_.store(limit);
  }
  bool spent() const { return elapsed_s() > limit_s_.load(); }
  double elapsed_s() const { return std::chrono::duration<double>(Clock::now() - start_).count(); }
  std::string describe() const {
    char text[120];
    const double limit = limit_s_.load();
    if (options_.max_seconds > 0.0 && limit == options_.max_seconds)
      std::snprintf(text, sizeof text, "stopped at the time budget, the cap of %.3g s (algorithm2 took %.3g s)", limit,
                    algorithm2_s_);
    else
      std::snprintf(text, sizeof text, "stopped at the time budget, %.3g s (%.3g x algorithm2's %.3g s)", limit,
                    options_.max_time_ratio, algorithm2_s_);
    return text;
  }

 private:
  const PortfolioOptions& options_;
  Clock::time_point start_;
  double algorithm2_s_ = 0.0;  // written before limit_s_ is, read after it is
  std::atomic<double> limit_s_{INFINITY};
};

}  // namespace

void PortfolioOptions::validate() const {
  if (threads < 0) throw std::invalid_argument("PortfolioOptions.threads must be >= 0 (0: one per core)");
  if (!(max_time_ratio >= 0.0) || !std::isfinite(max_time_ratio))
    throw std::invalid_argument("PortfolioOptions.max_time_ratio must be a finite number >= 0 (0: no limit)");
  if (!(min_budget_s >= 0.0) || !std::isfinite(min_budget_s))
    throw std::invalid_argument("PortfolioOptions.min_budget_s must be a finite number >= 0");
  if (!(max_seconds >= 0.0) || !std::isfinite(max_seconds))
    throw std::invalid_argument("PortfolioOptions.max_seconds must be a finite number >= 0 (0: no cap)");
}

Portfolio::Portfolio(PortfolioOptions options) : options_(options) { options_.validate(); }

std::vector<std::pair<std::string, std::unique_ptr<Planner>>> Portfolio::strategies() {
  std::vector<std::pair<std::string, std::unique_ptr<Planner>>> out;
  out.emplace_back("algorithm2", std::make_unique<Algorithm2>());
  // First of the others: over the 11 shared goals x 16 sizes from-above won
  // 53 of the 80 plans it finished when it was started last, and the time
  // budget stopped it in the other 96.
  out.emplace_back("from-above", std::make_unique<FromAbove>());
  out.emplace_back("algorithm2-levelled x1", make_algorithm2_levelled(1.0));
  out.emplace_back("algorithm2-levelled x2", make_algorithm2_levelled(2.0));
  return out;
}

PlanResult Portfolio::plan(const PlanRequest& request, const PlanCallbacks& callbacks) const {
  const Mesh mesh(request.geometry);
  validate_plan_request(request, mesh);
  const auto list = strategies();
  const std::size_t n = list.size();
  std::vector<StrategyOutcome> outcomes(n);
  std::mutex mutex;  // serialises the callbacks and the shared fields below
  std::exception_ptr cancelled;
  // Each strategy's own progress, 0..1; the portfolio reports their mean,
  // which rises as any of them does (a strategy counts 1 once it ends).
  std::vector<double> fractions(n, 0.0);
  const auto report = [&](std::size_t k, double fraction, const std::string& what) {  // with `mutex` held
    fractions[k] = std::max(fractions[k], fraction);
    double sum = 0.0;
    for (double f : fractions) sum += f;
    callbacks.progress(sum / double(n), list[k].first + ": " + what);
  };
  std::atomic<std::size_t> next{0};
  StrategyBudget budget(options_, Clock::now());
  const auto user_cancelled = [&] { return callbacks.cancelled && callbacks.cancelled(); };

  const auto run = [&](std::size_t k) {
    if (k != 0 && budget.spent()) {
      outcomes[k].not_started = true;
      const std::lock_guard<std::mutex> lock(mutex);
      if (callbacks.progress) report(k, 1.0, "not started");
      return;
    }
    PlanCallbacks own;
    // Strategy 0 is Algorithm 2, which always runs to its end.
    own.cancelled = [&, k] { return user_cancelled() || (k != 0 && budget.spent()); };
    // One strategy's snapshots stream as it goes, so a watcher sees the surface form.
    if (k == 0 && callbacks.snapshot)
      own.snapshot = [&](const DeviceState& state) {
        const std::lock_guard<std::mutex> lock(mutex);
        callbacks.snapshot(state);
      };
    if (callbacks.progress)
      own.progress = [&, k](double fraction, const std::string& what) {
        const std::lock_guard<std::mutex> lock(mutex);
        report(k, std::clamp(fraction, 0.0, 1.0), what);
      };
    StrategyOutcome& out = outcomes[k];
    const double started_s = budget.elapsed_s();
    try {
      out.result = list[k].second->plan(request, own);
    } catch (const PlanCancelled& stopped) {
      if (user_cancelled()) {
        const std::lock_guard<std::mutex> lock(mutex);
        cancelled = std::current_exception();
      } else if (stopped.partial()) {
        // Stopped at the budget: its plan so far is a plan too, and may
        // already beat Algorithm 2's (an anytime strategy).
        out.result = *stopped.partial();
        out.stopped_at_budget = true;
      }
      out.error = budget.describe();
    } catch (const std::exception& e) {
      out.error = e.what();
    }
    if (out.result) out.score = plan_score(request, mesh, out.result->final_state);
    out.seconds = budget.elapsed_s() - started_s;
    if (k == 0 && out.result) budget.algorithm2_took(out.seconds);
    const std::lock_guard<std::mutex> lock(mutex);
    if (callbacks.progress) report(k, 1.0, out.result ? "finished" : "stopped");
  };
  const auto worker = [&] {
    for (std::size_t k; (k = next.fetch_add(1)) < n;) run(k);
  };
  // Algorithm 2 runs alone first: its time sets the others' budget, and a
  // strategy beside it slows it (at 9 x 12 by up to 1.5 x, sharing the
  // machine's memory), which would stretch the budget with it.
  run(next.fetch_add(1));
  const int hardware = int(std::max(1u, std::thread::hardware_concurrency()));
  const int threads = std::max(1, std::min(options_.threads > 0 ? options_.threads : hardware, int(n)));
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) pool.emplace_back(worker);
  worker();
  for (auto& t : pool) t.join();
  if (cancelled) std::rethrow_exception(cancelled);

  // The best score wins; ties go to the earlier strategy (Algorithm 2 first).
  std::size_t best = n;
  std::string note = "strategies:";
  for (std::size_t k = 0; k < n; ++k) {
    char line[200];
    if (outcomes[k].result)
      std::snprintf(line, sizeof line, " %s %.4f in %.3g s%s", list[k].first.c_str(), outcomes[k].score,
                    outcomes[k].seconds, outcomes[k].stopped_at_budget ? " (its plan so far, stopped at the time budget)" : "");
    else if (outcomes[k].not_started)
      std::snprintf(line, sizeof line, " %s not started (the time budget was spent)", list[k].first.c_str());
    else
      std::snprintf(line, sizeof line, " %s failed (%.100s)", list[k].first.c_str(), outcomes[k].error.c_str());
    if (k) note += ';';
    note += line;
    if (outcomes[k].result && (best == n || outcomes[k].score > outcomes[best].score)) best = k;
  }
  if (best == n) throw std::runtime_error("portfolio: no strategy finished a plan (" + note + ")");
  PlanResult result = std::move(*outcomes[best].result);
  result.note = "chose " + list[best].first + "; " + note;
  if (callbacks.snapshot) callbacks.snapshot(result.final_state);
  return result;
}

namespace {
const bool registered = (register_planner("portfolio", [] { return std::make_unique<Portfolio>(); }), true);
}  // namespace

}  // namespace hj
