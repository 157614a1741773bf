// A render's device jobs (render_loop.h): a run (a capture at rest, the
// plan's actions, a capture), the probe (a capture at rest, then each
// pressure and a capture), each submitted to the device queue and waited
// for, cancelled when the render is.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "auth.h"
#include "device_queue.h"
#include "model/action.h"

namespace hj::server {

// The actions a job carried out (its steps less the capture at rest).
int actions_done(const hapticjam::v1::Job& job);
// A job the device failed at one of the plan's actions after carrying out
// at least one (not at a capture, and not cancelled or interrupted).
bool refused_part_way(const hapticjam::v1::Job& job, size_t actions);

// A run's job: a capture at rest labelled "NAME at rest", the steps, a capture "NAME".
hapticjam::v1::Plan run_job_plan(const std::string& name, const std::vector<Action>& steps);
// The probe's job: a capture at rest, then each pressure and a capture.
hapticjam::v1::Plan probe_job_plan(const std::string& name, const std::vector<Action>& probe);

struct RenderJobHooks {
  std::function<void(const hapticjam::v1::Job& job)> queued;   // once, when submitted
  std::function<bool()> cancelled;                             // polled while the job runs
  std::function<void(const hapticjam::v1::Job& job)> progress;  // each change seen
};

// Submits `plan` as a job named `name` and waits for it to end; cancels it
// once hooks.cancelled says so. @throws ServiceError UNAVAILABLE when the
// server shuts down, and what DeviceQueue::submit throws.
hapticjam::v1::Job run_device_job(DeviceQueue& queue, const Caller& caller, const std::string& name,
                                  const hapticjam::v1::Plan& plan, const RenderJobHooks& hooks);

// A job that did not end with its captures ends the render: CANCELLED if
// the caller cancelled it, else ABORTED, naming the job and how it ended.
[[noreturn]] void throw_unfinished(const hapticjam::v1::Job& job, const std::string& what, bool caller_cancelled);

}  // namespace hj::server
