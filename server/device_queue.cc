#include "device_queue.h"

#include "json_log.h"
#include "model/mesh.h"
#include "model/parameters.h"
#include "proto_convert.h"
#include "service_error.h"

namespace hj::server {

namespace v1 = ::hapticjam::v1;
using grpc::StatusCode;

namespace {

// A shutdown does not wait longer than this for the device's vent.
constexpr std::chrono::milliseconds kShutdownVentTimeout{2000};
// Checking a step needs the cells and nodes only: the coarsest mesh.
constexpr int kValidationSegments = 2;

// A job's place in the queue: the running job is 0, the next one 1
// (`active` lists the running job first).
int queue_position(const std::vector<StoredJob>& active, std::size_t index) {
  return int(index) + (active.front().state == v1::JOB_STATE_RUNNING ? 0 : 1);
}

// A job's name is a short label: bounded, and no control characters (it
// goes into logs and tables).
void check_job_name(const std::string& name, int max_bytes) {
  if (int(name.size()) > max_bytes)
    throw ServiceError(StatusCode::INVALID_ARGUMENT, "job name is " + std::to_string(name.size()) +
                                                         " bytes, over the server's limit of " +
                                                         std::to_string(max_bytes) + " (--max-job-name-bytes)");
  for (std::size_t i = 0; i < name.size(); ++i)
    if (static_cast<unsigned char>(name[i]) < 0x20 || name[i] == 0x7f)
      throw ServiceError(StatusCode::INVALID_ARGUMENT,
                         "job name has a control character at byte " + std::to_string(i));
}

}  // namespace

DeviceQueue::DeviceQueue(JobStore& store, device::DeviceLink* link, DeviceQueueOptions options)
    : store_(store), link_(link), options_(std::move(options)) {}

DeviceQueue::~DeviceQueue() { stop(); }

void DeviceQueue::start(std::function<void(bool)> on_serving) {
  on_serving_ = std::move(on_serving);
  if (on_serving_) on_serving_(false);
  store_.prune(options_.prune);
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
  // The safe state before the link closes; the halt keeps the runner's next
  // step unsent. (A crash or kill is covered by the device's own watchdog.)
  if (link_ && link_->connected()) {
    try {
      link_->halt_and_vent(std::min(options_.vent_timeout, kShutdownVentTimeout));
      log_event("device_vented", {{"by", "shutdown"}});
    } catch (const device::DeviceError& e) {
      log_event("device_vent_failed", {{"error", e.what()}, {"by", "shutdown"}});
    }
  }
  // Then the link: a command in flight fails at once instead of holding the runner.
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

void DeviceQueue::require_device(const char* action) {
  if (!link_)
    throw ServiceError(StatusCode::FAILED_PRECONDITION,
                       std::string("no device attached (start the server with --device) to ") + action);
  if (!connected_) throw ServiceError(StatusCode::FAILED_PRECONDITION, std::string("device offline: cannot ") + action);
}

v1::Job DeviceQueue::submit(const Caller& caller, const std::string& name, const v1::Plan& plan) {
  check_job_name(name, options_.limits.max_job_name_bytes);
  if (plan.steps_size() == 0) throw ServiceError(StatusCode::INVALID_ARGUMENT, "plan has no steps");
  if (plan.steps_size() > options_.limits.max_job_steps)
    throw ServiceError(StatusCode::INVALID_ARGUMENT, "plan has " + std::to_string(plan.steps_size()) +
                                                         " steps, over the server's limit of " +
                                                         std::to_string(options_.limits.max_job_steps));
  std::lock_guard lock(mutex_);
  require_device("submit a job");
  require_store("submit a job");
  if (emergency_stopped_ || store_.paused())
    throw ServiceError(StatusCode::FAILED_PRECONDITION, "queue paused: " + store_.pause_reason());

  // Every step against the device's own limits, before anything is queued.
  const device::DeviceStatus status = link_->status();
  if (status.rows < 1 || status.cols < 1 || !(status.cell_mm > 0.0))
    throw ServiceError(StatusCode::FAILED_PRECONDITION, "device reported no array size or cell size");
  const Mesh mesh(ArrayGeometry{status.rows, status.cols, status.cell_mm / 1000.0, kValidationSegments});
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
                       "device queue full: " + std::to_string(options_.max_queued) + " jobs waiting (--device-queue-size)");
  const std::int64_t id = store_.add(caller.name, name, plan);
  log_event("job_queued", {{"job", id}, {"owner", caller.name}, {"steps", plan.steps_size()}});
  changed();
  const auto jobs = store_.active();
  for (size_t i = 0; i < jobs.size(); ++i)
    if (jobs[i].id == id) return to_proto(jobs[i], queue_position(jobs, i));
  return to_proto(*store_.find(id), -1);
}

v1::Job DeviceQueue::cancel(const Caller& caller, std::int64_t id) {
  std::lock_guard lock(mutex_);
  require_store("cancel a job");
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
    if (jobs[i].id == id) position = queue_position(jobs, i);
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
  for (size_t i = 0; i < jobs.size(); ++i) *out.add_jobs() = to_proto(jobs[i], queue_position(jobs, i));
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
  if (!link_) throw ServiceError(StatusCode::FAILED_PRECONDITION, "no device attached to stop");
  const std::string why = "emergency stop by " + caller.name + (reason.empty() ? "" : ": " + reason);
  // Vent first, under no lock of the queue's (a step or a store write in
  // progress must not delay it); the link's halt keeps every later step unsent.
  std::string vent_error;
  try {
    link_->halt_and_vent(options_.vent_timeout);
    log_event("device_vented", {{"by", caller.name}, {"emergency", true}});
  } catch (const device::DeviceError& e) {
    vent_error = e.what();
  }
  record_stop(why, vent_error);
  if (!vent_error.empty())
    throw ServiceError(StatusCode::FAILED_PRECONDITION,
                       "could not vent the device (" + vent_error +
                           "); no step is sent, the queue is paused and the device is vented when it reconnects");
  return device_status();
}

void DeviceQueue::record_stop(const std::string& why, const std::string& vent_error) {
  std::unique_lock lock(mutex_);
  emergency_stopped_ = true;
  if (!vent_error.empty()) {
    need_vent_ = true;
    last_error_ = "emergency vent failed: " + vent_error;
  }
  try {
    interrupt_and_pause(why, why + "; an operator must resume the queue (ResumeQueue)");
  } catch (const StoreError& e) {
    // The array is vented and halted already; the record is what failed.
    store_failed_ = true;
    last_error_ = std::string("job database: ") + e.what();
    log_event("job_database_failed", {{"error", e.what()}});
    lock.unlock();
    report_serving();
    lock.lock();
  }
  changed();
}

v1::QueueState DeviceQueue::resume(const Caller& caller) {
  {
    std::lock_guard lock(mutex_);
    require_device("resume the queue");
    try {
      // A job the failed database could not end is not run again.
      if (store_failed_) store_.interrupt_running("the job database failed while the job ran");
      store_.set_paused(false);
    } catch (const StoreError& e) {
      throw ServiceError(StatusCode::UNAVAILABLE,
                         std::string("the job database still fails, the queue stays paused: ") + e.what());
    }
    link_->release_halt();
    emergency_stopped_ = false;
    store_failed_ = false;
    log_event("queue_resumed", {{"by", caller.name}});
    changed();
  }
  report_serving();
  return queue_state(0);
}

void DeviceQueue::require_store(const char* action) {
  if (store_failed_)
    throw ServiceError(StatusCode::UNAVAILABLE, std::string("cannot ") + action + ": " + last_error_ +
                                                    "; an operator must resume the queue (ResumeQueue) once it is fixed");
}

}  // namespace hj::server
