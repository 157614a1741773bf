// One render job (proto/hapticjam/v1/render_service.proto) in library calls
// and device jobs: plan the targets, run the plan and a capture as a job of
// the device queue (every step checked against the device first; a cancel,
// an emergency stop or a link drop ends the job and so the render), compare
// the capture with the goal at the mesh points (metrics/height_error.h),
// correct (move the targets by the error, learned_targets; or refit the
// device model on the captures so far and plan with it, render_calibration.h;
// or both) and repeat, until the error stops falling or the iteration limit.
#pragma once

#include <Eigen/Core>
#include <functional>
#include <string>

#include "auth.h"
#include "device_queue.h"
#include "hapticjam/v1/render_service.pb.h"
#include "plan/default_planner.h"
#include "proto_convert.h"

namespace hj::server {

struct RenderSetup {
  ArrayConfig array;        // the planner's array and model
  Eigen::MatrixXd goal_mm;  // the goal at the mesh points
  std::string planner = kRenderPlanner;
  int iterations = 5;
  hapticjam::v1::RenderCorrection correction = hapticjam::v1::RENDER_CORRECTION_BOTH;
  // Above 1: a device seldom moves by all of a target's change (a plan pins
  // and jams at discrete steps), so a gain of 1 converges slowly.
  double gain = 1.5;
  std::string name = "render";
  bool keep_camera_plane = false;  // compare the captures without fitting the camera's plane out
  int fit_threads = 0;             // of the model fit (MODEL, BOTH); 0: one per core
};

struct RenderHooks {
  std::function<void(hapticjam::v1::RenderEvent event)> emit;  // progress and iterations, in order
  std::function<bool()> cancelled;                             // polled while planning and while a job runs
};

// @throws ServiceError: FAILED_PRECONDITION (the device's array is another
//         size), ABORTED (an iteration's job did not finish), CANCELLED, and
//         what DeviceQueue::submit throws; hj::PlanCancelled is turned into CANCELLED.
hapticjam::v1::RenderResult run_render(const RenderSetup& setup, DeviceQueue& queue, const Caller& caller,
                                       const RenderHooks& hooks);

}  // namespace hj::server
