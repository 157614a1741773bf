#include "render_jobs.h"

#include <algorithm>
#include <chrono>

#include "job_store.h"
#include "proto_convert.h"
#include "service_error.h"

namespace hj::server {

namespace v1 = ::hapticjam::v1;
using grpc::StatusCode;

namespace {

void add_capture(const std::string& label, v1::Plan& plan) {
  v1::Step* capture = plan.add_steps();
  capture->mutable_capture();
  capture->set_label(label);
}

}  // namespace

int actions_done(const v1::Job& job) { return std::max(0, job.steps_done() - 1); }

bool refused_part_way(const v1::Job& job, size_t actions) {
  return job.state() == v1::JOB_STATE_FAILED && actions_done(job) > 0 && size_t(actions_done(job)) < actions;
}

v1::Plan run_job_plan(const std::string& name, const std::vector<Action>& steps) {
  v1::Plan plan;
  add_capture(name + " at rest", plan);
  for (const Action& a : steps) action_to_proto(a, plan.add_steps());
  add_capture(name, plan);
  return plan;
}

v1::Plan probe_job_plan(const std::string& name, const std::vector<Action>& probe) {
  v1::Plan plan;
  add_capture(name + " at rest", plan);
  for (const Action& a : probe) {
    action_to_proto(a, plan.add_steps());
    add_capture(name + " at " + a.describe(), plan);
  }
  return plan;
}

v1::Job run_device_job(DeviceQueue& queue, const Caller& caller, const std::string& name, const v1::Plan& plan,
                       const RenderJobHooks& hooks) {
  const v1::Job queued = queue.submit(caller, name, plan);
  hooks.queued(queued);
  std::uint64_t seen = 0;
  bool cancel_sent = false;
  for (;;) {
    v1::Job job = queue.get(queued.id());
    if (is_finished(job.state())) return job;
    if (!cancel_sent && hooks.cancelled()) {
      cancel_sent = true;
      try {
        queue.cancel(caller, queued.id());
      } catch (const ServiceError&) {
        // It ended meanwhile: the next get() says how.
      }
    }
    hooks.progress(job);
    seen = queue.wait_for_change(seen, std::chrono::milliseconds(200));
    if (queue.stopping()) throw ServiceError(StatusCode::UNAVAILABLE, "the server is shutting down");
  }
}

void throw_unfinished(const v1::Job& job, const std::string& what, bool caller_cancelled) {
  const bool cancelled = job.state() == v1::JOB_STATE_CANCELLED && caller_cancelled;
  throw ServiceError(cancelled ? StatusCode::CANCELLED : StatusCode::ABORTED,
                     what + ": device job " + std::to_string(job.id()) + " ended " + v1::JobState_Name(job.state()) +
                         (job.error().empty() ? std::string() : ": " + job.error()));
}

}  // namespace hj::server
