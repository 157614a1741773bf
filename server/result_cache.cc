#include "result_cache.h"

#include <cstdio>

namespace hj::server {

std::string content_hash(const std::string& bytes) {
  // FNV-1a 64 from two different offset bases; the second also mixes in the
  // position, so the two halves are not simple functions of each other.
  std::uint64_t a = 14695981039346656037ull, b = 0x9e3779b97f4a7c15ull;
  constexpr std::uint64_t prime = 1099511628211ull;
  std::uint64_t position = 0;
  for (unsigned char c : bytes) {
    a = (a ^ c) * prime;
    b = (b ^ (c + (++position << 8))) * prime;
  }
  char out[33];
  std::snprintf(out, sizeof out, "%016llx%016llx", (unsigned long long)a, (unsigned long long)b);
  return out;
}

std::shared_ptr<const hapticjam::v1::PlanResult> ResultCache::find(const std::string& key) {
  std::lock_guard lock(mutex_);
  const auto found = index_.find(key);
  if (found == index_.end()) return nullptr;
  order_.splice(order_.begin(), order_, found->second);
  return found->second->second;
}

void ResultCache::insert(const std::string& key, std::shared_ptr<const hapticjam::v1::PlanResult> result) {
  if (capacity_ <= 0) return;
  std::lock_guard lock(mutex_);
  if (const auto found = index_.find(key); found != index_.end()) {
    found->second->second = std::move(result);
    order_.splice(order_.begin(), order_, found->second);
    return;
  }
  order_.emplace_front(key, std::move(result));
  index_[key] = order_.begin();
  while (int(order_.size()) > capacity_) {
    index_.erase(order_.back().first);
    order_.pop_back();
  }
}

int ResultCache::size() const {
  std::lock_guard lock(mutex_);
  return int(order_.size());
}

}  // namespace hj::server
