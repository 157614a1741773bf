#include "calib/replay_tally.h"

#include <ctime>

namespace hj {

void ReplayTally::add(const std::string& session, double cpu_s, bool ok, bool warm) {
  std::lock_guard lock(mutex_);
  Entry* entry = nullptr;
  for (auto& e : entries_)
    if (e.session == session) entry = &e;
  if (!entry) entry = &entries_.emplace_back(Entry{session});
  ++entry->replays;
  if (!ok) ++entry->failed, entry->failed_cpu_s += cpu_s;
  if (!warm) ++entry->cold, entry->cold_cpu_s += cpu_s;
  entry->cpu_s += cpu_s;
}

std::vector<ReplayTally::Entry> ReplayTally::entries() const {
  std::lock_guard lock(mutex_);
  return entries_;
}

long ReplayTally::replays() const {
  long n = 0;
  for (const auto& e : entries()) n += e.replays;
  return n;
}

double ReplayTally::cpu_s() const {
  double s = 0.0;
  for (const auto& e : entries()) s += e.cpu_s;
  return s;
}

double thread_cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

}  // namespace hj
