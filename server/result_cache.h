// Finished planning results by content hash of their request (goal bytes or
// map + region, array, planner, options), least recently used dropped first,
// so zooming back to a region is answered at once.
#pragma once

#include <cstdint>
#include <list>
#include <memory>
#include <mutex>
#include <string>
#include <unordered_map>

#include "hapticjam/v1/planning_service.pb.h"

namespace hj::server {

// A 128-bit content hash (two independent 64-bit FNV-1a variants) as 32 hex digits.
std::string content_hash(const std::string& bytes);

class ResultCache {
 public:
  // capacity 0 disables the cache.
  explicit ResultCache(int capacity) : capacity_(capacity) {}

  std::shared_ptr<const hapticjam::v1::PlanResult> find(const std::string& key);
  void insert(const std::string& key, std::shared_ptr<const hapticjam::v1::PlanResult> result);
  int size() const;

 private:
  using Entry = std::pair<std::string, std::shared_ptr<const hapticjam::v1::PlanResult>>;
  const int capacity_;
  mutable std::mutex mutex_;
  std::list<Entry> order_;  // most recently used first
  std::unordered_map<std::string, std::list<Entry>::iterator> index_;
};

}  // namespace hj::server
