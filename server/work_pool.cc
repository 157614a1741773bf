#include "work_pool.h"

#include <stdexcept>
#include <string>

namespace hj::server {

WorkPool::WorkPool(int workers, int queue_size) : queue_size_(queue_size) {
  if (workers < 1) throw std::invalid_argument("workers must be at least 1, got " + std::to_string(workers));
  if (queue_size < 0) throw std::invalid_argument("queue size must not be negative, got " + std::to_string(queue_size));
  for (int i = 0; i < workers; ++i) threads_.emplace_back([this] { run(); });
}

WorkPool::~WorkPool() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
    tasks_.clear();
  }
  wake_.notify_all();
  for (auto& t : threads_) t.join();
}

bool WorkPool::try_submit(std::function<void()> task) {
  {
    std::unique_lock lock(mutex_);
    const bool room = idle_changed_.wait_for(
        lock, kFullGrace, [&] { return stopping_ || int(tasks_.size()) < queue_size_ + idle_; });
    if (stopping_ || !room) return false;
    tasks_.push_back(std::move(task));
  }
  wake_.notify_one();
  return true;
}

int WorkPool::waiting() const {
  std::lock_guard lock(mutex_);
  return int(tasks_.size());
}

void WorkPool::run() {
  for (;;) {
    std::function<void()> task;
    {
      std::unique_lock lock(mutex_);
      ++idle_;
      idle_changed_.notify_all();
      wake_.wait(lock, [&] { return stopping_ || !tasks_.empty(); });
      --idle_;
      if (stopping_) return;
      task = std::move(tasks_.front());
      tasks_.pop_front();
    }
    task();
  }
}

}  // namespace hj::server
