// A fixed pool of worker threads fed by a bounded queue: planning runs here,
// never on gRPC's threads, so the number of simulations at once is bounded
// and a burst beyond the queue is refused at once instead of piling up.
#pragma once

#include <chrono>
#include <condition_variable>
#include <deque>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace hj::server {

class WorkPool {
 public:
  // @throws std::invalid_argument if workers < 1 or queue_size < 0.
  WorkPool(int workers, int queue_size);
  // Finishes the running tasks, drops the waiting ones.
  ~WorkPool();
  WorkPool(const WorkPool&) = delete;
  WorkPool& operator=(const WorkPool&) = delete;

  // Queues `task`; false (and nothing queued) when every worker is busy and
  // queue_size tasks already wait. A worker that has just published its
  // answer needs a moment to come back for the next task, so a full pool is
  // given kFullGrace for one to free up before the refusal.
  bool try_submit(std::function<void()> task);

  int workers() const { return int(threads_.size()); }
  int queue_size() const { return queue_size_; }
  int waiting() const;

 private:
  static constexpr std::chrono::milliseconds kFullGrace{100};
  void run();

  const int queue_size_;
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  std::condition_variable idle_changed_;
  std::deque<std::function<void()>> tasks_;
  bool stopping_ = false;
  int idle_ = 0;  // workers waiting for a task
  std::vector<std::thread> threads_;
};

}  // namespace hj::server
