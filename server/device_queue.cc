#include "device_queue.h"

#include "json_log.h"
#include "model/mesh.h"
#include "model/parameters.h"
#include "proto_convert.h"
#include "service_error.h"

namespace hj::server {

namespace v1 = ::hapticjam::v1;
using grpc::StatusCode;

DeviceQueue::DeviceQueue(JobStore& store, device::DeviceLink* link, DeviceQueueOptions options)
    : store_(store), link_(link), options_(std::move(options)) {}

DeviceQueue::~DeviceQueue() { stop(); }

void DeviceQueue::start(std::function<void(bool)> on_connection) {
  on_connection_ = std::move(on_connection);
  if (on_connection_) on_connection_(false);
  if (link_) {
    link_->on_connection_change([this](bool connected) { connection_changed(connected); });
    link_->start();
  }
  runner_ = std::thread([this] { run(); });
}

void DeviceQueue::stop() {
  {
    std::lock_guard lock(mutex_);
    if (stopping_ && !runner_.joinable()) return;
    stopping_ = true;
    changed();
  }
  // The link first: a command in flight fails at once instead of holding the runner.
  if (link_) link_->stop();
  if (runner_.joinable()) runner_.join();
}

bool DeviceQueue::stopping() const {
  std::lock_guard lock(mutex_);
  return stopping_;
}

void DeviceQueue::changed() {
  ++version_;
  wake_.notify_all();
}

std::uint64_t DeviceQueue::wait_for_change(std::uint64_t seen, std::chrono::milliseconds timeout) {
  std::unique_lock lock(mutex_);
  wake_.wait_for(lock, timeout, [&] { return version_ > seen || stopping_; });
  return version_;
}

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

void DeviceQueue::connection_changed(bool connected) {
  {
    std::lock_guard lock(mutex_);
    connected_ = connected;
    if (connected) {
      need_vent_ = true;  // first thing on every (re)connection: the safe state
    } else {
      need_vent_ = true;
      if (running_id_ != 0 && !running_aborted_) {
        const std::string why = "the device link dropped during the job";
        abort_running(v1::JOB_STATE_INTERRUPTED, why);
        pause("job " + std::to_string(running_id_) + " was interrupted: " + why +
              "; the device is vented on reconnect and an operator must resume the queue (ResumeQueue)");
      }
    }
    log_event("device_link", {{"connected", connected}});
    changed();
  }
  if (on_connection_) on_connection_(connected);
}

// The runner: vents when needed, then runs the oldest queued job whenever
// the device is connected and the queue is not paused.
void DeviceQueue::run() {
  std::unique_lock lock(mutex_);
  while (!stopping_) {
    if (connected_ && need_vent_) {
      const std::uint64_t seen = version_;
      // Failed: retry after a pause, or at once when the link comes back.
      if (!vent_now(lock))
        wake_.wait_for(lock, std::chrono::milliseconds(500), [&] { return stopping_ || version_ > seen + 1; });
      continue;
    }
    const bool can_run = connected_ && !store_.paused() && !emergency_stopped_;
    const auto queued = can_run ? store_.active() : std::vector<StoredJob>{};
    if (queued.empty()) {
      const std::uint64_t seen = version_;
      wake_.wait_for(lock, std::chrono::milliseconds(500), [&] { return stopping_ || version_ != seen; });
      continue;
    }
    run_job(lock, queued.front().id);
  }
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

void DeviceQueue::run_job(std::unique_lock<std::mutex>& lock, std::int64_t id) {
  const v1::Plan plan = store_.plan(id);
  store_.set_state(id, v1::JOB_STATE_RUNNING);
  running_id_ = id;
  running_aborted_ = false;
  log_event("job_started", {{"job", id}, {"steps", plan.steps_size()}});
  changed();

  std::string error;
  bool fault = false;  // the link failed: interrupt and pause
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
  } catch (const device::DeviceError& e) {
    error = e.what();
    fault = e.kind() != device::DeviceError::Kind::kRefused;
  } catch (const std::exception& e) {
    error = e.what();
  }
  lock.lock();
  if (stopping_ && !running_aborted_) {
    // Left `running`: the next start reports it interrupted.
  } else if (!error.empty()) {
    last_error_ = error;
    need_vent_ = true;
    if (fault) {
      abort_running(v1::JOB_STATE_INTERRUPTED, "device: " + error);
      if (!store_.paused()) pause("job " + std::to_string(id) + " was interrupted: " + error + "; an operator must resume the queue (ResumeQueue)");
    } else {
      abort_running(v1::JOB_STATE_FAILED, "device refused: " + error);
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

void DeviceQueue::require_device(const char* action) {
  if (!link_)
    throw ServiceError(StatusCode::FAILED_PRECONDITION,
                       std::string("no device attached (start the server with --device) to ") + action);
  if (!connected_) throw ServiceError(StatusCode::FAILED_PRECONDITION, std::string("device offline: cannot ") + action);
}

v1::Job DeviceQueue::submit(const Caller& caller, const std::string& name, const v1::Plan& plan) {
  if (plan.steps_size() == 0) throw ServiceError(StatusCode::INVALID_ARGUMENT, "plan has no steps");
  if (plan.steps_size() > options_.limits.max_job_steps)
    throw ServiceError(StatusCode::INVALID_ARGUMENT, "plan has " + std::to_string(plan.steps_size()) +
                                                         " steps, over the server's limit of " +
                                                         std::to_string(options_.limits.max_job_steps));
  std::lock_guard lock(mutex_);
  require_device("submit a job");
  if (emergency_stopped_ || store_.paused())
    throw ServiceError(StatusCode::FAILED_PRECONDITION, "queue paused: " + store_.pause_reason());

  // Every step against the device's own limits, before anything is queued.
  const device::DeviceStatus status = link_->status();
  if (status.rows < 1 || status.cols < 1)
    throw ServiceError(StatusCode::FAILED_PRECONDITION, "device reported no array size");
  const Mesh mesh(ArrayGeometry{status.rows, status.cols, 0.038, 2});
  SurfaceParameters limits;
  if (status.max_pressure_pa > 0.0) limits.max_pressure_pa = status.max_pressure_pa;
  for (int i = 0; i < plan.steps_size(); ++i) {
    const std::string where = "step " + std::to_string(i);
    try {
      const DeviceStep step = step_from_proto(plan.steps(i), where);
      if (!step.capture) step.action.validate(mesh, limits);
    } catch (const std::invalid_argument& e) {
      const std::string what = e.what();
      throw ServiceError(StatusCode::INVALID_ARGUMENT,
                         what.rfind(where, 0) == 0 ? what : where + " (device " + std::to_string(status.rows) + " x " +
                                                                std::to_string(status.cols) + "): " + what);
    }
  }
  if (store_.queued_count() >= options_.max_queued)
    throw ServiceError(StatusCode::RESOURCE_EXHAUSTED,
                       "device queue full: " + std::to_string(options_.max_queued) + " jobs waiting (--queue-size)");
  const std::int64_t id = store_.add(caller.name, name, plan);
  log_event("job_queued", {{"job", id}, {"owner", caller.name}, {"steps", plan.steps_size()}});
  changed();
  const auto jobs = store_.active();
  for (size_t i = 0; i < jobs.size(); ++i)
    if (jobs[i].id == id) return to_proto(jobs[i], int(i) + (jobs.front().state == v1::JOB_STATE_RUNNING ? 0 : 1));
  return to_proto(*store_.find(id), -1);
}

v1::Job DeviceQueue::cancel(const Caller& caller, std::int64_t id) {
  std::lock_guard lock(mutex_);
  const auto job = store_.find(id);
  if (!job) throw ServiceError(StatusCode::NOT_FOUND, "no job " + std::to_string(id));
  if (job->owner != caller.name && caller.role < Role::kAdmin)
    throw ServiceError(StatusCode::PERMISSION_DENIED, "job " + std::to_string(id) + " belongs to \"" + job->owner +
                                                          "\"; cancelling another caller's job needs admin");
  if (is_finished(job->state))
    throw ServiceError(StatusCode::FAILED_PRECONDITION, "job " + std::to_string(id) + " has already ended (" +
                                                            v1::JobState_Name(job->state) + ")");
  const std::string why = "cancelled by " + caller.name;
  if (id == running_id_) abort_running(v1::JOB_STATE_CANCELLED, why);
  else store_.set_state(id, v1::JOB_STATE_CANCELLED, why);
  log_event("job_cancelled", {{"job", id}, {"by", caller.name}});
  changed();
  return to_proto(*store_.find(id), -1);
}

v1::Job DeviceQueue::get(std::int64_t id) {
  std::lock_guard lock(mutex_);
  const auto job = store_.find(id);
  if (!job) throw ServiceError(StatusCode::NOT_FOUND, "no job " + std::to_string(id));
  int position = -1;
  const auto jobs = store_.active();
  for (size_t i = 0; i < jobs.size(); ++i)
    if (jobs[i].id == id) position = int(i) + (jobs.front().state == v1::JOB_STATE_RUNNING ? 0 : 1);
  v1::Job out = to_proto(*job, position);
  for (auto& frame : store_.captures(id)) *out.add_captures() = std::move(frame);
  return out;
}

v1::Job DeviceQueue::to_proto(const StoredJob& job, int position) const {
  v1::Job out;
  out.set_id(job.id);
  out.set_owner(job.owner);
  out.set_name(job.name);
  out.set_state(job.state);
  out.set_position(is_finished(job.state) ? -1 : position);
  out.set_steps_done(job.steps_done);
  out.set_steps_total(job.steps_total);
  out.set_error(job.error);
  out.set_submitted_unix_ms(job.submitted_unix_ms);
  out.set_finished_unix_ms(job.finished_unix_ms);
  return out;
}

v1::QueueState DeviceQueue::queue_state(int recent_finished) {
  std::lock_guard lock(mutex_);
  v1::QueueState out;
  const auto jobs = store_.active();
  const int first = !jobs.empty() && jobs.front().state == v1::JOB_STATE_RUNNING ? 0 : 1;
  for (size_t i = 0; i < jobs.size(); ++i) *out.add_jobs() = to_proto(jobs[i], int(i) + first);
  if (recent_finished > 0)
    for (const auto& job : store_.recent_finished(recent_finished)) *out.add_jobs() = to_proto(job, -1);
  out.set_paused(store_.paused() || emergency_stopped_);
  out.set_pause_reason(store_.pause_reason());
  out.set_device_connected(connected_);
  return out;
}

v1::DeviceStatus DeviceQueue::device_status() {
  v1::DeviceStatus out;
  if (link_) {
    const device::DeviceStatus s = link_->status();
    out.set_endpoint(s.endpoint);
    out.set_rows(s.rows), out.set_cols(s.cols);
    out.set_pressure_pa(s.pressure_pa), out.set_max_pressure_pa(s.max_pressure_pa);
    for (int r = 0; r < s.rows; ++r)
      for (int c = 0; c < s.cols; ++c)
        if (size_t(r * s.cols + c) < s.cell_jammed.size() && s.cell_jammed[size_t(r * s.cols + c)]) {
          auto* cell = out.add_jammed_cells();
          cell->set_row(r), cell->set_col(c);
        }
    for (int a = 0; a <= s.rows; ++a)
      for (int b = 0; b <= s.cols; ++b)
        if (size_t(a * (s.cols + 1) + b) < s.node_pinned.size() && s.node_pinned[size_t(a * (s.cols + 1) + b)]) {
          auto* node = out.add_pinned_nodes();
          node->set_a(a), node->set_b(b);
        }
    if (s.last_capture) capture_to_proto(*s.last_capture, out.mutable_last_capture());
    out.set_last_error(s.last_error);
  } else {
    out.set_last_error("no device attached (start the server with --device)");
  }
  std::lock_guard lock(mutex_);
  out.set_connected(connected_);
  if (out.last_error().empty()) out.set_last_error(last_error_);
  out.set_queue_paused(store_.paused() || emergency_stopped_);
  out.set_pause_reason(store_.pause_reason());
  out.set_emergency_stopped(emergency_stopped_);
  return out;
}

v1::DeviceStatus DeviceQueue::emergency_stop(const Caller& caller, const std::string& reason) {
  {
    std::lock_guard lock(mutex_);
    if (!link_) throw ServiceError(StatusCode::FAILED_PRECONDITION, "no device attached to stop");
    const std::string why = "emergency stop by " + caller.name + (reason.empty() ? "" : ": " + reason);
    emergency_stopped_ = true;
    abort_running(v1::JOB_STATE_INTERRUPTED, why);
    pause(why + "; an operator must resume the queue (ResumeQueue)");
    changed();
  }
  // Straight to the link, not through the runner: it may be inside a step.
  try {
    link_->vent(options_.vent_timeout);
    log_event("device_vented", {{"by", caller.name}, {"emergency", true}});
  } catch (const device::DeviceError& e) {
    std::lock_guard lock(mutex_);
    need_vent_ = true;
    last_error_ = std::string("emergency vent failed: ") + e.what();
    throw ServiceError(StatusCode::FAILED_PRECONDITION,
                       std::string("could not vent the device (") + e.what() +
                           "); the queue is paused and the device is vented when it reconnects");
  }
  return device_status();
}

v1::QueueState DeviceQueue::resume(const Caller& caller) {
  {
    std::lock_guard lock(mutex_);
    require_device("resume the queue");
    emergency_stopped_ = false;
    store_.set_paused(false);
    log_event("queue_resumed", {{"by", caller.name}});
    changed();
  }
  return queue_state(0);
}

}  // namespace hj::server
