// PlanningService (proto/hapticjam/v1/planning_service.proto): authorises,
// answers from the cache or runs run_planning() on the work pool, streams
// its progress and snapshots, and stops it when the caller cancels or its
// deadline passes.
#pragma once

#include "auth.h"
#include "goal_source.h"
#include "hapticjam/v1/planning_service.grpc.pb.h"
#include "server_limits.h"
#include "result_cache.h"
#include "streamed_work.h"
#include "work_pool.h"

namespace hj::server {

class PlanningServiceImpl final : public hapticjam::v1::PlanningService::Service {
 public:
  PlanningServiceImpl(const Authenticator& auth, const MapStore& maps, const ServerLimits& limits, WorkPool& pool,
                      ResultCache& cache)
      : auth_(auth), maps_(maps), limits_(limits), pool_(pool), cache_(cache) {}

  grpc::Status Plan(grpc::ServerContext* context, const hapticjam::v1::PlanRequest* request,
                    grpc::ServerWriter<hapticjam::v1::PlanEvent>* writer) override;
  grpc::Status Preview(grpc::ServerContext* context, const hapticjam::v1::PreviewRequest* request,
                       hapticjam::v1::PreviewResponse* response) override;
  grpc::Status ListPlanners(grpc::ServerContext* context, const hapticjam::v1::ListPlannersRequest* request,
                            hapticjam::v1::ListPlannersResponse* response) override;

 private:
  using Work = StreamedWork<hapticjam::v1::PlanEvent, std::shared_ptr<const hapticjam::v1::PlanResult>>;
  // Plans (or finds in the cache) and returns the result; streams events to
  // `writer` when it is set.
  grpc::Status plan_or_cached(grpc::ServerContext* context, const hapticjam::v1::PreviewRequest& request,
                              bool snapshots, grpc::ServerWriter<hapticjam::v1::PlanEvent>* writer,
                              hapticjam::v1::PlanResult* result);

  const Authenticator& auth_;
  const MapStore& maps_;
  const ServerLimits& limits_;
  WorkPool& pool_;
  ResultCache& cache_;
};

}  // namespace hj::server
