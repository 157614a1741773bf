#include "calib/parallel_for.h"

#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <exception>
#include <thread>
#include <vector>

namespace hj {

int default_thread_count() {
  if (const char* env = std::getenv("HJ_THREADS"); env && std::atoi(env) > 0) return std::atoi(env);
  return std::max(1u, std::thread::hardware_concurrency());
}

void parallel_for(int count, const std::function<void(int)>& job, int threads) {
  if (count <= 0) return;
  if (threads <= 0) threads = default_thread_count();
  threads = std::min(threads, count);
  std::vector<std::exception_ptr> errors(count);
  std::atomic<int> next{0};
  auto worker = [&] {
    for (int i = next++; i < count; i = next++) {
      try {
        job(i);
      } catch (...) {
        errors[i] = std::current_exception();
      }
    }
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) pool.emplace_back(worker);
  worker();
  for (auto& t : pool) t.join();
  for (const auto& e : errors)
    if (e) std::rethrow_exception(e);
}

}  // namespace hj
