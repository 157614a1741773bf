// The shared device: a persistent queue of jobs (plans) run one at a time, in
// submission order, on the array behind a DeviceLink. A runner thread
// executes jobs step by step; a link drop or an emergency stop interrupts the
// running job and pauses the queue, the device is vented (its safe state)
// before anything else runs, and only a resume lets jobs run again. Roles
// (docs/safety.md): an operator or admin may stop and resume; a previewer
// may do neither.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <mutex>
#include <thread>

#include "auth.h"
#include "device/device_link.h"
#include "hapticjam/v1/device_service.pb.h"
#include "job_store.h"
#include "server_limits.h"

namespace hj::server {

struct DeviceQueueOptions {
  int max_queued = 64;  // jobs waiting; one more is RESOURCE_EXHAUSTED
  std::chrono::milliseconds step_timeout{60'000};
  std::chrono::milliseconds capture_timeout{30'000};
  std::chrono::milliseconds vent_timeout{10'000};
  PrunePolicy prune;  // finished jobs kept (--keep-jobs, --keep-days)
  ServerLimits limits;
};

class DeviceQueue {
 public:
  // `link` may be null (no device attached); it must outlive the queue.
  DeviceQueue(JobStore& store, device::DeviceLink* link, DeviceQueueOptions options);
  ~DeviceQueue();
  DeviceQueue(const DeviceQueue&) = delete;
  DeviceQueue& operator=(const DeviceQueue&) = delete;

  // `on_serving` is told whether the device service can serve (connected,
  // and no database failure waiting for an operator) on every change.
  void start(std::function<void(bool serving)> on_serving = {});
  // Vents the device (halting its link first, so no later step goes out),
  // then stops the runner (a running job's current step finishes, the job is
  // left `running` in the store and found `interrupted` by the next start)
  // and the link.
  void stop();

  // Each throws ServiceError with the status code the API promises.
  hapticjam::v1::Job submit(const Caller& caller, const std::string& name, const hapticjam::v1::Plan& plan);
  hapticjam::v1::Job cancel(const Caller& caller, std::int64_t id);
  hapticjam::v1::Job get(std::int64_t id);
  hapticjam::v1::QueueState queue_state(int recent_finished);
  hapticjam::v1::DeviceStatus device_status();
  hapticjam::v1::DeviceStatus emergency_stop(const Caller& caller, const std::string& reason);
  hapticjam::v1::QueueState resume(const Caller& caller);

  // A counter that grows with every change of the queue; waits until it
  // passes `seen` or the timeout ends, and returns it.
  std::uint64_t wait_for_change(std::uint64_t seen, std::chrono::milliseconds timeout);
  bool stopping() const;

 private:
  // The runner (device_queue_runner.cc).
  void run();
  void run_once(std::unique_lock<std::mutex>& lock);
  void run_job(std::unique_lock<std::mutex>& lock, std::int64_t id);
  bool vent_now(std::unique_lock<std::mutex>& lock);
  void store_failed(std::unique_lock<std::mutex>& lock, const std::string& what);
  void connection_changed(bool connected);
  void paused_by_drop();
  void report_serving();  // without mutex_
  // The stop's bookkeeping, after its vent (takes mutex_): stopped, the
  // running job interrupted, paused.
  void record_stop(const std::string& why, const std::string& vent_error);

  // With mutex_ held.
  void changed();
  // Ends the running job as `state` if it is still running.
  void abort_running(hapticjam::v1::JobState state, const std::string& why);
  // Ends the running job `interrupted` (if it runs) and pauses, in one transaction.
  void interrupt_and_pause(const std::string& why, const std::string& reason);
  void pause(const std::string& reason);
  hapticjam::v1::Job to_proto(const StoredJob& job, int position) const;
  void require_device(const char* action);
  void require_store(const char* action);

  JobStore& store_;
  device::DeviceLink* link_;
  const DeviceQueueOptions options_;
  std::function<void(bool)> on_serving_;

  mutable std::mutex mutex_;
  std::condition_variable wake_;
  std::uint64_t version_ = 0;
  bool stopping_ = false;
  bool connected_ = false;
  bool need_vent_ = true;        // vent before the next job (start-up, reconnect, a cancel or failure)
  bool emergency_stopped_ = false;
  bool store_failed_ = false;    // a database error paused the queue; cleared by resume
  std::int64_t running_id_ = 0;  // 0 = none
  bool running_aborted_ = false; // the running job was ended by cancel, drop or stop
  std::string last_error_;
  std::thread runner_;
};

}  // namespace hj::server
