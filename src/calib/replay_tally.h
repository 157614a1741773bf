// Where a fit's time goes: every session replay made through a ReplayOptions
// that points at a tally is counted here with the CPU time of its thread,
// per session, so that a report can say "N replays of jammed-sweep at s each".
#pragma once

#include <mutex>
#include <string>
#include <vector>

namespace hj {

class ReplayTally {
 public:
  struct Entry {
    std::string session;
    long replays = 0;
    long failed = 0;     // replays that threw (no equilibrium)
    double cpu_s = 0.0;  // thread CPU time of all its replays
    double failed_cpu_s = 0.0;  // ... of which in the failed ones
    long cold = 0;              // replays with no warm start (replay_session)
    double cold_cpu_s = 0.0;    // ... and their CPU time
  };

  // Thread-safe. warm: the replay was warm-started from another's trace.
  void add(const std::string& session, double cpu_s, bool ok, bool warm);
  // In order of first appearance.
  std::vector<Entry> entries() const;
  long replays() const;
  double cpu_s() const;

 private:
  mutable std::mutex mutex_;
  std::vector<Entry> entries_;
};

// CPU time of the calling thread, s.
double thread_cpu_seconds();

}  // namespace hj
