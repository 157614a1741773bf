// RenderService (proto/hapticjam/v1/render_service.proto): authorises an
// operator, reads the goal and array, and runs the render loop
// (render_loop.h) on the caller's stream, stopping it when the caller
// cancels or its deadline passes.
#pragma once

#include "auth.h"
#include "device_queue.h"
#include "goal_source.h"
#include "hapticjam/v1/render_service.grpc.pb.h"
#include "server_limits.h"

namespace hj::server {

// Iterations one render may ask for.
constexpr int kMaxRenderIterations = 20;

class RenderServiceImpl final : public hapticjam::v1::RenderService::Service {
 public:
  RenderServiceImpl(const Authenticator& auth, const MapStore& maps, const ServerLimits& limits, DeviceQueue& queue)
      : auth_(auth), maps_(maps), limits_(limits), queue_(queue) {}

  grpc::Status Render(grpc::ServerContext* context, const hapticjam::v1::RenderRequest* request,
                      grpc::ServerWriter<hapticjam::v1::RenderEvent>* writer) override;

 private:
  const Authenticator& auth_;
  const MapStore& maps_;
  const ServerLimits& limits_;
  DeviceQueue& queue_;
};

}  // namespace hj::server
