// CalibrationService (proto/hapticjam/v1/calibration_service.proto): the
// measurement workbench's compare, fit and diagnose on an uploaded dataset.
// Authorises (Compare: preview; Fit, Diagnose: operator), turns the upload
// into a Dataset (dataset_upload.h), runs the library's call on the work
// pool (refused with RESOURCE_EXHAUSTED when it is full), relays its progress
// and stops it, through ReplayOptions::interrupted, when the caller cancels
// or its deadline passes. One log line per call.
#pragma once

#include "auth.h"
#include "hapticjam/v1/calibration_service.grpc.pb.h"
#include "server_limits.h"
#include "work_pool.h"

namespace hj::server {

class CalibrationServiceImpl final : public hapticjam::v1::CalibrationService::Service {
 public:
  CalibrationServiceImpl(const Authenticator& auth, const ServerLimits& limits, WorkPool& pool)
      : auth_(auth), limits_(limits), pool_(pool) {}

  grpc::Status Compare(grpc::ServerContext* context, const hapticjam::v1::CompareRequest* request,
                       grpc::ServerWriter<hapticjam::v1::CompareEvent>* writer) override;
  grpc::Status Fit(grpc::ServerContext* context, const hapticjam::v1::FitRequest* request,
                   grpc::ServerWriter<hapticjam::v1::FitEvent>* writer) override;
  grpc::Status Diagnose(grpc::ServerContext* context, const hapticjam::v1::DiagnoseRequest* request,
                        grpc::ServerWriter<hapticjam::v1::DiagnoseEvent>* writer) override;

 private:
  const Authenticator& auth_;
  const ServerLimits& limits_;
  WorkPool& pool_;
};

}  // namespace hj::server
