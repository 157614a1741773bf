#include "plan/portfolio.h"

#include <atomic>
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
  std::string error;
};

}  // namespace

void PortfolioOptions::validate() const {
  if (threads < 0) throw std::invalid_argument("PortfolioOptions.threads must be >= 0 (0: one per core)");
}

Portfolio::Portfolio(PortfolioOptions options) : options_(options) { options_.validate(); }

std::vector<std::pair<std::string, std::unique_ptr<Planner>>> Portfolio::strategies() {
  std::vector<std::pair<std::string, std::unique_ptr<Planner>>> out;
  out.emplace_back("algorithm2", std::make_unique<Algorithm2>());
  out.emplace_back("algorithm2-levelled x1", make_algorithm2_levelled(1.0));
  out.emplace_back("algorithm2-levelled x2", make_algorithm2_levelled(2.0));
  out.emplace_back("from-above", std::make_unique<FromAbove>());
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
  int finished = 0;
  std::atomic<std::size_t> next{0};

  const auto run = [&](std::size_t k) {
    PlanCallbacks own;
    own.cancelled = callbacks.cancelled;
    // One strategy's snapshots stream as it goes, so a watcher sees the surface form.
    if (k == 0 && callbacks.snapshot)
      own.snapshot = [&](const DeviceState& state) {
        const std::lock_guard<std::mutex> lock(mutex);
        callbacks.snapshot(state);
      };
    StrategyOutcome& out = outcomes[k];
    try {
      out.result = list[k].second->plan(request, own);
      out.score = plan_score(request, mesh, out.result->final_state);
    } catch (const PlanCancelled&) {
      const std::lock_guard<std::mutex> lock(mutex);
      cancelled = std::current_exception();
    } catch (const std::exception& e) {
      out.error = e.what();
    }
    const std::lock_guard<std::mutex> lock(mutex);
    ++finished;
    if (callbacks.progress) callbacks.progress(double(finished) / double(n), list[k].first + " finished");
  };
  const auto worker = [&] {
    for (std::size_t k; (k = next.fetch_add(1)) < n;) run(k);
  };
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
    char line[160];
    if (outcomes[k].result)
      std::snprintf(line, sizeof line, " %s %.4f", list[k].first.c_str(), outcomes[k].score);
    else
      std::snprintf(line, sizeof line, " %s failed (%.80s)", list[k].first.c_str(), outcomes[k].error.c_str());
    note += (k ? ";" : "") + std::string(line);
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
