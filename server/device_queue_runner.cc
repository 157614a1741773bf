// The device queue's runner thread and its reactions to faults: the link
// coming and going, a step failing, the job database failing.
#include "device_queue.h"
#include "json_log.h"
#include "proto_convert.h"

namespace hj::server {

namespace v1 = ::hapticjam::v1;

void DeviceQueue::pause(const std::string& reason) {
  store_.set_paused(true, reason);
  log_event("queue_paused", {{"reason", reason}});
}

void DeviceQueue::abort_running(v1::JobState state, const std::string& why) {
  if (running_id_ == 0 || running_aborted_) return;
  store_.set_state(running_id_, state, why);
  running_aborted_ = true;
  log_event("job_ended", {{"job", running_id_}, {"state", v1::JobState_Name(state)}, {"error", why}});
}

void DeviceQueue::interrupt_and_pause(const std::string& why, const std::string& reason) {
  if (running_id_ != 0 && !running_aborted_) {
    store_.end_and_pause(running_id_, v1::JOB_STATE_INTERRUPTED, why, reason);
    running_aborted_ = true;
    log_event("job_ended", {{"job", running_id_}, {"state", "JOB_STATE_INTERRUPTED"}, {"error", why}});
    log_event("queue_paused", {{"reason", reason}});
  } else {
    pause(reason);
  }
}

void DeviceQueue::report_serving() {
  bool serving = false;
  {
    std::lock_guard lock(mutex_);
    serving = connected_ && !store_failed_;
  }
  if (on_serving_) on_serving_(serving);
}

void DeviceQueue::connection_changed(bool connected) {
  {
    std::lock_guard lock(mutex_);
    connected_ = connected;
    need_vent_ = true;  // first thing on every (re)connection: the safe state
    log_event("device_link", {{"connected", connected}});
    if (!connected && !store_failed_) {
      try {
        paused_by_drop();
      } catch (const StoreError& e) {
        store_failed_ = true;
        last_error_ = std::string("job database: ") + e.what();
        log_event("job_database_failed", {{"error", e.what()}});
      }
    }
    changed();
  }
  report_serving();
}

// A drop during a job interrupts it; a drop between jobs pauses the queue
// too, so nothing runs on a device that came back in an unknown state
// until an operator has looked.
void DeviceQueue::paused_by_drop() {
  if (running_id_ != 0 && !running_aborted_) {
    const std::string why = "the device link dropped during the job";
    interrupt_and_pause(why, "job " + std::to_string(running_id_) + " was interrupted: " + why +
                                 "; the device is vented on reconnect and an operator must resume the queue "
                                 "(ResumeQueue)");
  } else if (!store_.paused()) {
    pause("the device link dropped between jobs; the device is vented on reconnect and an operator must resume "
          "the queue (ResumeQueue)");
  }
}

// The runner: vents when needed, then runs the oldest queued job whenever
// the device is connected and the queue is not paused. A database error
// never ends the thread (store_failed).
void DeviceQueue::run() {
  std::unique_lock lock(mutex_);
  while (!stopping_) {
    try {
      run_once(lock);
    } catch (const StoreError& e) {
      if (!lock.owns_lock()) lock.lock();
      store_failed(lock, e.what());
    }
  }
}

void DeviceQueue::run_once(std::unique_lock<std::mutex>& lock) {
  if (connected_ && need_vent_) {
    const std::uint64_t seen = version_;
    // Failed: retry after a pause, or at once when the link comes back.
    if (!vent_now(lock))
      wake_.wait_for(lock, std::chrono::milliseconds(500), [&] { return stopping_ || version_ > seen + 1; });
    return;
  }
  const bool can_run = connected_ && !store_failed_ && !emergency_stopped_ && !store_.paused();
  const auto queued = can_run ? store_.active() : std::vector<StoredJob>{};
  if (queued.empty()) {
    const std::uint64_t seen = version_;
    wake_.wait_for(lock, std::chrono::milliseconds(500), [&] { return stopping_ || version_ != seen; });
    return;
  }
  run_job(lock, queued.front().id);
  store_.prune(options_.prune);
}

bool DeviceQueue::vent_now(std::unique_lock<std::mutex>& lock) {
  lock.unlock();
  std::string error;
  try {
    link_->vent(options_.vent_timeout);
  } catch (const device::DeviceError& e) {
    error = e.what();
  }
  lock.lock();
  if (error.empty()) {
    need_vent_ = false;
    log_event("device_vented");
  } else {
    last_error_ = "vent failed: " + error;
    log_event("device_vent_failed", {{"error", error}});
  }
  changed();
  return error.empty();
}

// A database error in the runner or a handler: the device is vented first;
// then the running job is ended `interrupted` and the queue paused if the
// database still takes the write (logged if not); the device service
// reports NOT_SERVING until an operator resumes the queue.
void DeviceQueue::store_failed(std::unique_lock<std::mutex>& lock, const std::string& what) {
  const bool first = !store_failed_;
  store_failed_ = true;
  last_error_ = "job database: " + what;
  log_event("job_database_failed", {{"error", what}});
  lock.unlock();
  if (first) report_serving();
  bool vented = false;
  if (link_ && link_->connected()) {
    try {
      link_->halt_and_vent(options_.vent_timeout);
      vented = true;
      log_event("device_vented", {{"by", "job database failure"}});
    } catch (const device::DeviceError& e) {
      log_event("device_vent_failed", {{"error", e.what()}});
    }
  }
  lock.lock();
  if (!vented) need_vent_ = true;
  const std::string why = "the job database failed: " + what;
  try {
    interrupt_and_pause(why, why + "; fix it, then an operator must resume the queue (ResumeQueue)");
  } catch (const StoreError& e) {
    log_event("job_database_write_failed", {{"job", running_id_}, {"error", e.what()}});
  }
  running_id_ = 0;
  running_aborted_ = false;
  changed();
  // Not again at once: the database may still be failing.
  wake_.wait_for(lock, std::chrono::milliseconds(500), [&] { return stopping_ || !store_failed_; });
}

void DeviceQueue::run_job(std::unique_lock<std::mutex>& lock, std::int64_t id) {
  v1::Plan plan;
  try {
    plan = store_.plan(id);
  } catch (const BadStoredPlan& e) {
    store_.set_state(id, v1::JOB_STATE_FAILED, e.what());
    log_event("job_ended", {{"job", id}, {"state", "JOB_STATE_FAILED"}, {"error", e.what()}});
    changed();
    return;
  }
  store_.set_state(id, v1::JOB_STATE_RUNNING);
  running_id_ = id;
  running_aborted_ = false;
  log_event("job_started", {{"job", id}, {"steps", plan.steps_size()}});
  changed();

  std::string error;
  bool fault = false;   // the link failed: interrupt and pause
  bool halted = false;  // an emergency stop refused the step (record_stop ends the job)
  bool vented = false;  // the device dropped the step: it vented (a stop's vent, or its watchdog)
  lock.unlock();
  try {
    // Every plan starts from the rest state.
    link_->vent(options_.vent_timeout);
    for (int i = 0; i < plan.steps_size(); ++i) {
      {
        std::lock_guard check(mutex_);
        if (running_aborted_ || stopping_) break;
      }
      const DeviceStep step = step_from_proto(plan.steps(i), "step " + std::to_string(i));
      if (step.capture) {
        const device::Capture capture = link_->capture(options_.capture_timeout);
        v1::CaptureFrame frame;
        capture_to_proto(capture, &frame);
        frame.set_step_index(i);
        frame.set_label(step.label);
        std::lock_guard store(mutex_);
        store_.add_capture(id, frame);
      } else {
        link_->execute(step.action, options_.step_timeout);
      }
      std::lock_guard progress(mutex_);
      if (!running_aborted_) store_.set_progress(id, i + 1);
      changed();
    }
  } catch (const StoreError&) {
    throw;  // run() vents and pauses
  } catch (const device::DeviceError& e) {
    error = e.what();
    // Not sent (halted), or dropped by a device that vented: most likely a stop in flight.
    vented = e.kind() == device::DeviceError::Kind::kVented;
    halted = vented || e.kind() == device::DeviceError::Kind::kHalted;
    fault = e.kind() != device::DeviceError::Kind::kRefused;
  } catch (const std::exception& e) {
    error = e.what();
  }
  lock.lock();
  if (stopping_ && !running_aborted_) {
    // Left `running`: the next start reports it interrupted.
  } else if (halted) {
    // The stop ends the job itself, with its reason, once its vent is
    // answered: at once when the device already vented, else within the vent's timeout.
    const auto bound = vented ? std::chrono::milliseconds(2000) : options_.vent_timeout + std::chrono::seconds(1);
    wake_.wait_for(lock, bound, [&] { return emergency_stopped_ || stopping_ || store_failed_; });
    need_vent_ = true;
    // No stop came (the device's watchdog vented): a fault.
    if (!running_aborted_)
      interrupt_and_pause("device: " + error, "job " + std::to_string(id) + " was interrupted: " + error +
                                                  "; an operator must resume the queue (ResumeQueue)");
  } else if (!error.empty()) {
    last_error_ = error;
    need_vent_ = true;
    if (!fault) {
      abort_running(v1::JOB_STATE_FAILED, "device refused: " + error);
    } else if (!running_aborted_) {
      interrupt_and_pause("device: " + error, "job " + std::to_string(id) + " was interrupted: " + error +
                                                  "; an operator must resume the queue (ResumeQueue)");
    } else if (!store_.paused()) {
      pause("job " + std::to_string(id) + " was interrupted: " + error +
            "; an operator must resume the queue (ResumeQueue)");
    }
  } else if (running_aborted_) {
    need_vent_ = true;  // cancelled or stopped part way: back to the safe state
  } else {
    abort_running(v1::JOB_STATE_DONE, "");
  }
  running_id_ = 0;
  running_aborted_ = false;
  changed();
}

}  // namespace hj::server
