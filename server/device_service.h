// DeviceService (proto/hapticjam/v1/device_service.proto): authorises each
// call by role and hands it to the DeviceQueue. WatchQueue streams are
// bounded (ServerLimits::max_watchers): each holds a server thread.
#pragma once

#include <atomic>

#include "auth.h"
#include "device_queue.h"
#include "hapticjam/v1/device_service.grpc.pb.h"

namespace hj::server {

class DeviceServiceImpl final : public hapticjam::v1::DeviceService::Service {
 public:
  DeviceServiceImpl(const Authenticator& auth, DeviceQueue& queue, const ServerLimits& limits)
      : auth_(auth), queue_(queue), limits_(limits) {}

  grpc::Status SubmitJob(grpc::ServerContext* context, const hapticjam::v1::SubmitJobRequest* request,
                         hapticjam::v1::SubmitJobResponse* response) override;
  grpc::Status WatchQueue(grpc::ServerContext* context, const hapticjam::v1::WatchQueueRequest* request,
                          grpc::ServerWriter<hapticjam::v1::QueueState>* writer) override;
  grpc::Status CancelJob(grpc::ServerContext* context, const hapticjam::v1::CancelJobRequest* request,
                         hapticjam::v1::CancelJobResponse* response) override;
  grpc::Status GetJob(grpc::ServerContext* context, const hapticjam::v1::GetJobRequest* request,
                      hapticjam::v1::Job* response) override;
  grpc::Status GetDeviceStatus(grpc::ServerContext* context, const hapticjam::v1::GetDeviceStatusRequest* request,
                               hapticjam::v1::DeviceStatus* response) override;
  grpc::Status EmergencyStop(grpc::ServerContext* context, const hapticjam::v1::EmergencyStopRequest* request,
                             hapticjam::v1::DeviceStatus* response) override;
  grpc::Status ResumeQueue(grpc::ServerContext* context, const hapticjam::v1::ResumeQueueRequest* request,
                           hapticjam::v1::QueueState* response) override;

 private:
  const Authenticator& auth_;
  DeviceQueue& queue_;
  const ServerLimits& limits_;
  std::atomic<int> watchers_{0};
};

}  // namespace hj::server
