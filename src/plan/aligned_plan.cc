#include "plan/aligned_plan.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <exception>
#include <mutex>
#include <optional>
#include <random>
#include <stdexcept>
#include <thread>

#include "model/mesh.h"

namespace hj {
namespace {

// The identity, then the candidates the criterion puts closer to the nodes
// than the identity, lowest cost first, at most `plans` of them (or, for the
// random control, `plans` of any cost).
std::vector<const AlignmentCandidate*> shortlist(const std::vector<AlignmentCandidate>& candidates,
                                                 const AlignedPlanOptions& options) {
  std::vector<const AlignmentCandidate*> out{&candidates.front()};
  if (options.pick == AlignedPlanOptions::Pick::kRandom) {
    std::vector<const AlignmentCandidate*> others;
    for (std::size_t k = 1; k < candidates.size(); ++k) others.push_back(&candidates[k]);
    std::mt19937 random(options.seed);
    std::shuffle(others.begin(), others.end(), random);
    others.resize(std::min(others.size(), std::size_t(options.plans)));
    out.insert(out.end(), others.begin(), others.end());
    return out;
  }
  const double identity_cost = candidates.front().valley_cost;
  for (std::size_t k = 1; k < candidates.size() && int(out.size()) <= options.plans; ++k)
    if (candidates[k].valley_cost < identity_cost - 1e-9 * std::max(1.0, identity_cost)) out.push_back(&candidates[k]);
  return out;
}

// Runs fn(k) for k in [0, n) on up to `threads` threads (0: one per core).
template <typename Fn>
void run_parallel(std::size_t n, int threads, const Fn& fn) {
  std::atomic<std::size_t> next{0};
  const auto worker = [&] {
    for (std::size_t k; (k = next.fetch_add(1)) < n;) fn(k);
  };
  const int hardware = int(std::max(1u, std::thread::hardware_concurrency()));
  const int count = std::max(1, std::min(threads > 0 ? threads : hardware, int(n)));
  std::vector<std::thread> pool;
  for (int t = 1; t < count; ++t) pool.emplace_back(worker);
  worker();
  for (auto& t : pool) t.join();
}

}  // namespace

void AlignedPlanOptions::validate() const {
  align.validate();
  if (plans < 0) throw std::invalid_argument("AlignedPlanOptions.plans must be >= 0, got " + std::to_string(plans));
  if (threads < 0) throw std::invalid_argument("AlignedPlanOptions.threads must be >= 0 (0: one per core)");
  if (!(max_time_ratio >= 1.0) || !std::isfinite(max_time_ratio))
    throw std::invalid_argument("AlignedPlanOptions.max_time_ratio must be a finite number >= 1, got " +
                                std::to_string(max_time_ratio));
}

AlignedPlan plan_aligned(const std::string& planner, const HeightMap& source, const Region& window,
                         const PlanRequest& request, double relief_mm, const AlignedPlanOptions& options,
                         const PlanCallbacks& callbacks) {
  options.validate();
  (void)make_planner(planner);  // an unknown name fails before any work
  const Mesh mesh(request.geometry);
  const std::vector<AlignmentCandidate> candidates =
      alignment_candidates(source, window, mesh, relief_mm, options.align);
  const std::vector<const AlignmentCandidate*> chosen_few = shortlist(candidates, options);

  // Each shortlisted goal planned on its own, scored against its own window.
  struct Outcome {
    PlanRequest request;
    HeightMap goal;
    std::optional<PlanResult> result;
    PlannedCandidate record;
  };
  std::vector<Outcome> outcomes(chosen_few.size());
  std::mutex mutex;  // serialises progress and the cancellation below
  std::exception_ptr cancelled, identity_error;
  int finished = 0;
  using Clock = std::chrono::steady_clock;
  std::atomic<double> identity_seconds{-1.0};  // set when the unaligned plan ends
  run_parallel(chosen_few.size(), options.threads, [&](std::size_t k) {
    const AlignmentCandidate& c = *chosen_few[k];
    Outcome& out = outcomes[k];
    out.record = {c.transform, c.window, c.valley_cost, -INFINITY, "", 0.0};
    out.goal = crop(source, c.window);
    out.request = request;
    out.request.goal_mm = c.goal_mm;
    out.request.goal_image = out.goal.z;
    const auto start = Clock::now();
    const auto seconds = [&] { return std::chrono::duration<double>(Clock::now() - start).count(); };
    bool too_slow = false;
    PlanCallbacks own;
    own.cancelled = [&] {
      if (callbacks.cancelled && callbacks.cancelled()) return true;
      const double limit = identity_seconds.load();
      too_slow = k > 0 && limit >= 0.0 && seconds() > options.max_time_ratio * std::max(limit, 1.0);
      return too_slow;
    };
    try {
      out.result = make_planner(planner)->plan(out.request, own);
      out.record.score = plan_score(out.request, mesh, out.result->final_state);
    } catch (const PlanCancelled&) {
      if (too_slow) {
        out.record.error = "stopped at " + std::to_string(options.max_time_ratio) + " x the unaligned plan's time";
      } else {
        const std::lock_guard<std::mutex> lock(mutex);
        cancelled = std::current_exception();
      }
    } catch (const std::exception& e) {
      out.record.error = e.what();
      if (k == 0) identity_error = std::current_exception();
    }
    out.record.seconds = seconds();
    if (k == 0) identity_seconds = out.record.seconds;
    const std::lock_guard<std::mutex> lock(mutex);
    ++finished;
    if (callbacks.progress)
      callbacks.progress(double(finished) / double(chosen_few.size()),
                         k == 0 ? "unaligned goal planned" : "aligned candidate planned");
  });
  if (cancelled) std::rethrow_exception(cancelled);
  if (identity_error) std::rethrow_exception(identity_error);

  // The best score; the identity (first) wins ties, then the lower cost (the order).
  std::size_t best = 0;
  for (std::size_t k = 1; k < outcomes.size(); ++k)
    if (outcomes[k].result && outcomes[k].record.score > outcomes[best].record.score) best = k;
  AlignedPlan out;
  out.chosen = *chosen_few[best];
  out.goal = std::move(outcomes[best].goal);
  out.result = std::move(*outcomes[best].result);
  out.score = outcomes[best].record.score;
  out.unaligned_score = outcomes[0].record.score;
  out.candidates = int(candidates.size());
  for (const Outcome& o : outcomes) out.planned.push_back(o.record);
  if (callbacks.snapshot) callbacks.snapshot(out.result.final_state);
  return out;
}

}  // namespace hj
