#include "render_service.h"

#include <chrono>
#include <algorithm>
#include <cmath>
#include <thread>

#include "plan/planner.h"
#include "render_loop.h"
#include "request_context.h"
#include "service_error.h"
#include "shapes/resample.h"

namespace hj::server {

namespace v1 = ::hapticjam::v1;
using grpc::StatusCode;

namespace {

RenderSetup setup_from_proto(const v1::RenderRequest& request, const MapStore& maps, const ServerLimits& limits) {
  RenderSetup setup;
  try {
    setup.array = array_from_proto(request.array(), limits);
    const HeightMap goal = load_goal(request.goal(), maps, limits);
    setup.goal_mm = goal_to_mesh(goal, Mesh(setup.array.geometry), heights_from_proto(request.goal()),
                                 max_height_from_proto(request.goal().options()));
  } catch (const std::invalid_argument& e) {
    throw ServiceError(StatusCode::INVALID_ARGUMENT, e.what());
  }
  if (!request.planner().empty()) setup.planner = request.planner();
  if (request.iterations() < 0 || request.iterations() > kMaxRenderIterations)
    throw ServiceError(StatusCode::INVALID_ARGUMENT, "iterations must be within 1.." +
                                                         std::to_string(kMaxRenderIterations) + " (0 = 5), got " +
                                                         std::to_string(request.iterations()));
  if (request.iterations() > 0) setup.iterations = request.iterations();
  if (!(request.gain() >= 0.0 && request.gain() <= 2.0))
    throw ServiceError(StatusCode::INVALID_ARGUMENT, "gain must be within (0, 2] (0 = 1.5), got " +
                                                         std::to_string(request.gain()));
  if (request.gain() > 0.0) setup.gain = request.gain();
  switch (request.correction()) {
    case v1::RENDER_CORRECTION_UNSPECIFIED: setup.correction = v1::RENDER_CORRECTION_BOTH; break;
    case v1::RENDER_CORRECTION_TARGETS:
    case v1::RENDER_CORRECTION_NONE:
    case v1::RENDER_CORRECTION_MODEL:
    case v1::RENDER_CORRECTION_BOTH: setup.correction = request.correction(); break;
    default:
      throw ServiceError(StatusCode::INVALID_ARGUMENT,
                         "correction: unknown value " + std::to_string(request.correction()));
  }
  if (!request.name().empty()) setup.name = request.name();
  setup.keep_camera_plane = request.keep_camera_plane();
  setup.fit_threads = calibration_thread_count(0, limits, int(std::max(1u, std::thread::hardware_concurrency())));
  return setup;
}

}  // namespace

grpc::Status RenderServiceImpl::Render(grpc::ServerContext* context, const v1::RenderRequest* request,
                                       grpc::ServerWriter<v1::RenderEvent>* writer) {
  RequestContext rc(context, "Render");
  return rc.finish([&] {
    const Caller& caller = rc.authorize(auth_, Role::kOperator, "Render");
    const RenderSetup setup = setup_from_proto(*request, maps_, limits_);
    make_planner(setup.planner);  // an unknown planner before anything runs
    bool gone = false;
    const auto deadline = context->deadline();
    RenderHooks hooks;
    hooks.emit = [&](v1::RenderEvent event) {
      if (!gone && !writer->Write(event)) gone = true;
    };
    hooks.cancelled = [&] { return gone || context->IsCancelled() || std::chrono::system_clock::now() > deadline; };
    v1::RenderEvent last;
    *last.mutable_result() = run_render(setup, queue_, caller, hooks);
    rc.note("iterations", last.result().iterations());
    rc.note("mae_mm", last.result().error().mae_mm());
    if (!writer->Write(last)) throw ServiceError(StatusCode::CANCELLED, "the caller went away");
  });
}

}  // namespace hj::server
