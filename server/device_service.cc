#include "device_service.h"

#include "request_context.h"
#include "service_error.h"

namespace hj::server {

namespace v1 = ::hapticjam::v1;

namespace {

// One of the bounded WatchQueue slots, held for the stream's life.
class WatcherSlot {
 public:
  WatcherSlot(std::atomic<int>& count, int max) : count_(count) {
    if (count_.fetch_add(1) >= max) {
      count_.fetch_sub(1);
      throw ServiceError(grpc::StatusCode::RESOURCE_EXHAUSTED,
                         std::to_string(max) + " queue watchers already open, the server's limit (--max-watchers)");
    }
  }
  ~WatcherSlot() { count_.fetch_sub(1); }
  WatcherSlot(const WatcherSlot&) = delete;
  WatcherSlot& operator=(const WatcherSlot&) = delete;

 private:
  std::atomic<int>& count_;
};

}  // namespace

grpc::Status DeviceServiceImpl::SubmitJob(grpc::ServerContext* context, const v1::SubmitJobRequest* request,
                                          v1::SubmitJobResponse* response) {
  RequestContext rc(context, "SubmitJob");
  return rc.finish([&] {
    const Caller& caller = rc.authorize(auth_, Role::kOperator, "SubmitJob");
    *response->mutable_job() = queue_.submit(caller, request->name(), request->plan());
    rc.note("job", response->job().id());
  });
}

grpc::Status DeviceServiceImpl::WatchQueue(grpc::ServerContext* context, const v1::WatchQueueRequest* request,
                                           grpc::ServerWriter<v1::QueueState>* writer) {
  RequestContext rc(context, "WatchQueue");
  return rc.finish([&] {
    rc.authorize(auth_, Role::kPreview, "WatchQueue");
    if (request->recent_finished() < 0 || request->recent_finished() > limits_.max_recent_finished)
      throw ServiceError(grpc::StatusCode::INVALID_ARGUMENT,
                         "recent_finished = " + std::to_string(request->recent_finished()) + ": must be 0 .. " +
                             std::to_string(limits_.max_recent_finished));
    const WatcherSlot slot(watchers_, limits_.max_watchers);
    std::uint64_t seen = queue_.wait_for_change(0, std::chrono::milliseconds(0));
    if (!writer->Write(queue_.queue_state(request->recent_finished()))) return;
    // Every change, until the caller leaves or the server stops.
    while (!context->IsCancelled() && !queue_.stopping()) {
      const std::uint64_t now = queue_.wait_for_change(seen, std::chrono::milliseconds(200));
      if (now == seen) continue;
      seen = now;
      if (!writer->Write(queue_.queue_state(request->recent_finished()))) return;
    }
  });
}

grpc::Status DeviceServiceImpl::CancelJob(grpc::ServerContext* context, const v1::CancelJobRequest* request,
                                          v1::CancelJobResponse* response) {
  RequestContext rc(context, "CancelJob");
  return rc.finish([&] {
    const Caller& caller = rc.authorize(auth_, Role::kOperator, "CancelJob");
    rc.note("job", request->id());
    *response->mutable_job() = queue_.cancel(caller, request->id());
  });
}

grpc::Status DeviceServiceImpl::GetJob(grpc::ServerContext* context, const v1::GetJobRequest* request,
                                       v1::Job* response) {
  RequestContext rc(context, "GetJob");
  return rc.finish([&] {
    rc.authorize(auth_, Role::kPreview, "GetJob");
    *response = queue_.get(request->id());
  });
}

grpc::Status DeviceServiceImpl::GetDeviceStatus(grpc::ServerContext* context, const v1::GetDeviceStatusRequest*,
                                                v1::DeviceStatus* response) {
  RequestContext rc(context, "GetDeviceStatus");
  return rc.finish([&] {
    rc.authorize(auth_, Role::kPreview, "GetDeviceStatus");
    *response = queue_.device_status();
  });
}

grpc::Status DeviceServiceImpl::EmergencyStop(grpc::ServerContext* context, const v1::EmergencyStopRequest* request,
                                              v1::DeviceStatus* response) {
  RequestContext rc(context, "EmergencyStop");
  return rc.finish([&] {
    // Whoever may run jobs may stop the array, and clear their stop (ResumeQueue).
    const Caller& caller = rc.authorize(auth_, Role::kOperator, "EmergencyStop");
    *response = queue_.emergency_stop(caller, request->reason());
  });
}

grpc::Status DeviceServiceImpl::ResumeQueue(grpc::ServerContext* context, const v1::ResumeQueueRequest*,
                                            v1::QueueState* response) {
  RequestContext rc(context, "ResumeQueue");
  return rc.finish([&] {
    const Caller& caller = rc.authorize(auth_, Role::kOperator, "ResumeQueue");
    *response = queue_.resume(caller);
  });
}

}  // namespace hj::server
