// Runs independent jobs (one session replay, one Jacobian column) on a small
// pool of std::threads, one per core by default.
#pragma once

#include <functional>

namespace hj {

// Calls job(i) for i in [0, count) on up to `threads` threads (0: one per
// hardware core). Returns when all are done; if any job threw, rethrows the
// exception of the lowest index after the others finished.
void parallel_for(int count, const std::function<void(int)>& job, int threads = 0);

// Threads parallel_for uses when asked for 0: the hardware cores, or the
// HJ_THREADS environment variable when it is set to a positive number.
int default_thread_count();

}  // namespace hj
