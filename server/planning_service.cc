#include "planning_service.h"

#include <chrono>

#include "calib/step_json.h"
#include "json_log.h"
#include "plan/refused_json.h"
#include "planning.h"
#include "request_context.h"
#include "service_error.h"
#include "shapes/goal_importer.h"

namespace hj::server {

namespace v1 = ::hapticjam::v1;
using Clock = std::chrono::steady_clock;

// Preview's mesh when the request leaves array.segments unset: planning
// time grows steeply with the segments (6 x 8 cells: seconds at 2, minutes at 4).
constexpr int kPreviewSegments = 2;

namespace {

std::shared_ptr<const v1::PlanResult> result_to_proto(const Mesh& mesh, const PlanningOutput& out) {
  auto result = std::make_shared<v1::PlanResult>();
  result->mutable_plan()->set_planner(out.planner);
  nlohmann::json steps = nlohmann::json::array();
  for (const Action& a : out.result.steps) {
    action_to_proto(a, result->mutable_plan()->add_steps());
    steps.push_back(action_to_step_json(a));
  }
  result->set_steps_json(steps.dump());
  result->set_refused_json(refused_to_json(out.result.refused).dump());
  snapshot_to_proto(mesh, out.result.final_state, int(out.result.steps.size()), result->mutable_predicted());
  for (int i = 0; i < out.goal_mm.rows(); ++i)
    for (int j = 0; j < out.goal_mm.cols(); ++j) result->add_goal_heights_mm(out.goal_mm(i, j));
  if (out.correlation.value) result->set_correlation(*out.correlation.value);
  else result->set_correlation_undefined(out.correlation.undefined_reason);
  result->set_laplace_mean(out.laplace_mean);
  return result;
}

// The request with defaults filled in, as the cache key's content.
std::string cache_key(const v1::PreviewRequest& request) {
  v1::PreviewRequest canonical = request;
  if (canonical.planner().empty()) canonical.set_planner(kDefaultPlanner);
  std::string bytes;
  google::protobuf::io::StringOutputStream stream(&bytes);
  google::protobuf::io::CodedOutputStream coded(&stream);
  coded.SetSerializationDeterministic(true);
  canonical.SerializeToCodedStream(&coded);
  coded.Trim();
  return content_hash(bytes);
}

}  // namespace

grpc::Status PlanningServiceImpl::plan_or_cached(grpc::ServerContext* context, const v1::PreviewRequest& request,
                                                 bool snapshots, grpc::ServerWriter<v1::PlanEvent>* writer,
                                                 v1::PlanResult* result) {
  const auto start = Clock::now();
  const std::string key = cache_key(request);
  if (auto cached = cache_.find(key)) {
    *result = *cached;
    result->set_cached(true);
    result->set_seconds(std::chrono::duration<double>(Clock::now() - start).count());
    return grpc::Status::OK;
  }

  auto work = std::make_shared<Work>(*context, limits_.max_plan_time, "--max-plan-seconds");
  const bool streaming = writer != nullptr;
  auto task = [work, request, snapshots, streaming, key, &maps = maps_, &limits = limits_, &cache = cache_] {
    if (work->should_stop()) return work->finish({grpc::StatusCode::CANCELLED, "cancelled before it started"});
    try {
      PlanningInput input{array_from_proto(request.array(), limits), load_goal(request.goal(), maps, limits),
                          max_height_from_proto(request.goal().options()),
                          request.planner().empty() ? std::string(kDefaultPlanner) : request.planner(),
                          heights_from_proto(request.goal())};
      const Mesh mesh(input.array.geometry);
      int settled = 0;
      PlanCallbacks callbacks;
      callbacks.cancelled = [&] { return work->should_stop(); };
      if (streaming) {
        callbacks.progress = [&](double fraction, const std::string& what) {
          v1::PlanEvent event;
          event.mutable_progress()->set_fraction(fraction);
          event.mutable_progress()->set_message(what);
          work->push(std::move(event));
        };
        if (snapshots)
          callbacks.snapshot = [&](const DeviceState& state) {
            v1::PlanEvent event;
            snapshot_to_proto(mesh, state, ++settled, event.mutable_snapshot());
            work->push(std::move(event));
          };
      }
      auto result = result_to_proto(mesh, run_planning(input, callbacks));
      cache.insert(key, result);
      work->finish(grpc::Status::OK, std::move(result));
    } catch (const PlanCancelled&) {
      work->finish(work->stopped_status("planning"));
    } catch (...) {
      work->finish(status_from_current_exception());
    }
  };
  if (!pool_.try_submit(std::move(task)))
    return {grpc::StatusCode::RESOURCE_EXHAUSTED,
            "planning queue full: " + std::to_string(pool_.workers()) + " workers busy and " +
                std::to_string(pool_.queue_size()) + " requests waiting (--workers, --queue-size)"};

  const grpc::Status status = relay_until_done(context, writer, *work, "the plan");
  if (!status.ok()) return status;
  *result = *work->result;
  result->set_seconds(std::chrono::duration<double>(Clock::now() - start).count());
  return grpc::Status::OK;
}

grpc::Status PlanningServiceImpl::Plan(grpc::ServerContext* context, const v1::PlanRequest* request,
                                       grpc::ServerWriter<v1::PlanEvent>* writer) {
  RequestContext rc(context, "Plan");
  return rc.finish([&] {
    rc.authorize(auth_, Role::kPreview, "Plan");
    v1::PreviewRequest key;
    *key.mutable_array() = request->array();
    *key.mutable_goal() = request->goal();
    key.set_planner(request->planner());
    v1::PlanEvent last;
    const grpc::Status status = plan_or_cached(context, key, !request->omit_snapshots(), writer, last.mutable_result());
    if (!status.ok()) throw ServiceError(status.error_code(), status.error_message());
    rc.note("cached", last.result().cached());
    if (!writer->Write(last)) throw ServiceError(grpc::StatusCode::CANCELLED, "the caller went away");
  });
}

grpc::Status PlanningServiceImpl::Preview(grpc::ServerContext* context, const v1::PreviewRequest* request,
                                          v1::PreviewResponse* response) {
  RequestContext rc(context, "Preview");
  return rc.finish([&] {
    rc.authorize(auth_, Role::kPreview, "Preview");
    // Quick: a coarse mesh and the fastest planner unless the caller chose them.
    v1::PreviewRequest coarse = *request;
    if (coarse.array().segments() == 0) coarse.mutable_array()->set_segments(kPreviewSegments);
    if (coarse.planner().empty()) coarse.set_planner(kPreviewPlanner);
    v1::PlanResult result;
    const grpc::Status status = plan_or_cached(context, coarse, false, nullptr, &result);
    if (!status.ok()) throw ServiceError(status.error_code(), status.error_message());
    rc.note("cached", result.cached());
    *response->mutable_predicted() = std::move(*result.mutable_predicted());
    *response->mutable_goal_heights_mm() = std::move(*result.mutable_goal_heights_mm());
    if (result.has_correlation()) response->set_correlation(result.correlation());
    response->set_correlation_undefined(result.correlation_undefined());
    response->set_laplace_mean(result.laplace_mean());
    response->set_step_count(result.plan().steps_size());
    response->set_cached(result.cached());
    response->set_seconds(result.seconds());
  });
}

grpc::Status PlanningServiceImpl::ListPlanners(grpc::ServerContext* context, const v1::ListPlannersRequest*,
                                               v1::ListPlannersResponse* response) {
  RequestContext rc(context, "ListPlanners");
  return rc.finish([&] {
    rc.authorize(auth_, Role::kPreview, "ListPlanners");
    for (const auto& name : planner_names()) response->add_planners(name);
    for (const auto& name : maps_.names()) response->add_maps(name);
    for (const auto& ext : known_goal_extensions()) response->add_goal_extensions(ext);
  });
}

}  // namespace hj::server
