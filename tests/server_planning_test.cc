// PlanningService over gRPC against an in-process server: the streamed plan
// matches the library's own answer, cancellation and deadlines free the
// worker, a full queue is refused at once, repeats come from the cache, and
// bad requests are refused naming what is wrong.
#include <gtest/gtest.h>

#include <atomic>
#include <thread>

#include "metrics/correlation.h"
#include "metrics/laplace_predictor.h"
#include "plan/default_planner.h"
#include "plan/planner.h"
#include "server_fixture.h"
#include "shapes/goal_importer.h"
#include "shapes/resample.h"
#include "sim/surface_measures.h"

namespace hj {
namespace {

using namespace testing_support;
using grpc::StatusCode;

// A planner that never finishes on its own: it reports progress and polls
// for cancellation until it is stopped, so tests can hold a worker.
class EndlessPlanner final : public Planner {
 public:
  std::string name() const override { return "test-endless"; }
  PlanResult plan(const PlanRequest&, const PlanCallbacks& callbacks) const override {
    for (int n = 0;; ++n) {
      if (callbacks.cancelled && callbacks.cancelled()) throw PlanCancelled();
      if (callbacks.progress) callbacks.progress(0.0, "waiting " + std::to_string(n));
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
  }
};
const bool kEndlessRegistered =
    (register_planner("test-endless", [] { return std::make_unique<EndlessPlanner>(); }), true);

server::ServerOptions options(int workers, int queue_size, const std::filesystem::path& db) {
  server::ServerOptions o;
  o.workers = workers;
  o.queue_size = queue_size;
  o.db_file = db.string();
  return o;
}

v1::PlanRequest endless_request() {
  v1::PlanRequest r = plan_request(2, 2);
  r.set_planner("test-endless");
  return r;
}

// Reads events of an endless plan until its first progress (it holds a worker then).
void wait_until_running(grpc::ClientReader<v1::PlanEvent>& reader) {
  v1::PlanEvent event;
  ASSERT_TRUE(reader.Read(&event));
  ASSERT_TRUE(event.has_progress());
}

// Named: Algorithm 2 is deterministic, and each snapshot is its plan's next
// step (the portfolio streams Algorithm 2's, then its chosen final state).
TEST(ServerPlanning, StreamsProgressSnapshotsAndTheLibrarysResult) {
  ScratchDir dir;
  TestServer s(options(1, 4, dir.path / "q.db"), false);
  v1::PlanRequest request = plan_request(3, 4);
  request.mutable_array()->set_segments(2);
  request.set_planner("algorithm2");
  auto context = call();
  auto reader = s.planning->Plan(context.get(), request);
  int progress = 0, snapshots = 0, results = 0;
  double last_fraction = -1.0;
  v1::PlanResult result;
  for (v1::PlanEvent event; reader->Read(&event);) {
    if (event.has_progress()) {
      EXPECT_GE(event.progress().fraction(), last_fraction);
      last_fraction = event.progress().fraction();
      ++progress;
    } else if (event.has_snapshot()) {
      EXPECT_EQ(event.snapshot().heights_mm_size(), 7 * 9);  // (3*2+1) x (4*2+1) points
      EXPECT_EQ(event.snapshot().steps_applied(), ++snapshots);
    } else {
      result = event.result();
      ++results;
    }
  }
  const grpc::Status status = reader->Finish();
  ASSERT_TRUE(status.ok()) << status.error_message();
  EXPECT_GT(progress, 0);
  EXPECT_EQ(results, 1);
  EXPECT_EQ(snapshots, result.plan().steps_size());
  EXPECT_FALSE(result.cached());

  // The library, called directly on the same goal, gives the same plan and scores.
  const std::filesystem::path goal_file = dir.path / "bump.csv";
  std::ofstream(goal_file) << request.goal().file().content();
  const HeightMap goal = import_goal(goal_file);
  const ArrayGeometry g{3, 4, 0.038, 2};
  const Mesh mesh(g);
  const PlanResult plan = make_planner("algorithm2")->plan(
      {g, SurfaceParameters::paper_defaults(g), resample_to_mesh(goal, mesh, default_relief_mm(g)), {}});
  const Eigen::MatrixXd predicted = point_heights(mesh, plan.final_state.x) * 1000.0;
  const Correlation expected = correlate_with_goal(goal.z, predicted.colwise().reverse());
  ASSERT_TRUE(expected.value.has_value());
  ASSERT_TRUE(result.has_correlation());
  EXPECT_DOUBLE_EQ(result.correlation(), *expected.value);
  EXPECT_DOUBLE_EQ(result.laplace_mean(), laplace_mean(goal.z));
  ASSERT_EQ(result.plan().steps_size(), int(plan.steps.size()));
  EXPECT_EQ(result.predicted().heights_mm(5 * 9 + 4), predicted(5, 4));
  EXPECT_EQ(result.predicted().pressure_pa(), plan.final_state.pressure_pa);
  EXPECT_EQ(nlohmann::json::parse(result.steps_json()).size(), plan.steps.size());
}

// A Plan naming no planner gets the default (the portfolio, with streamed
// progress that rises); a Preview, the quick Algorithm 2.
TEST(ServerPlanning, ARequestNamingNoPlannerGetsTheDefaultAndAPreviewTheQuickOne) {
  ScratchDir dir;
  TestServer s(options(1, 4, dir.path / "q.db"), false);
  v1::PlanRequest request = plan_request(3, 4);
  request.mutable_array()->set_segments(2);
  auto context = call();
  auto reader = s.planning->Plan(context.get(), request);
  int progress = 0;
  double last_fraction = -1.0;
  v1::PlanResult result;
  for (v1::PlanEvent event; reader->Read(&event);) {
    if (event.has_progress()) {
      EXPECT_GE(event.progress().fraction(), last_fraction);
      EXPECT_LE(event.progress().fraction(), 1.0);
      last_fraction = event.progress().fraction();
      ++progress;
    } else if (event.has_result()) {
      result = event.result();
    }
  }
  ASSERT_TRUE(reader->Finish().ok());
  EXPECT_EQ(result.plan().planner(), kDefaultPlanner);
  EXPECT_GT(progress, 4);  // the strategies' own progress, not only their ends

  v1::PreviewRequest preview = preview_request(3, 4);
  preview.mutable_array()->set_segments(2);
  v1::PreviewResponse quick;
  ASSERT_TRUE(s.planning->Preview(call().get(), preview, &quick).ok());
  request.set_planner(kPreviewPlanner);
  auto named_context = call();
  auto named = s.planning->Plan(named_context.get(), request);
  v1::PlanResult algorithm2;
  for (v1::PlanEvent event; named->Read(&event);)
    if (event.has_result()) algorithm2 = event.result();
  ASSERT_TRUE(named->Finish().ok());
  EXPECT_EQ(quick.step_count(), algorithm2.plan().steps_size());
  EXPECT_EQ(quick.correlation(), algorithm2.correlation());
}

TEST(ServerPlanning, ARepeatedRequestComesFromTheCache) {
  ScratchDir dir;
  TestServer s(options(1, 4, dir.path / "q.db"), false);
  v1::PreviewRequest request = preview_request(2, 3);
  v1::PreviewResponse first, second, other;
  ASSERT_TRUE(s.planning->Preview(call().get(), request, &first).ok());
  ASSERT_TRUE(s.planning->Preview(call().get(), request, &second).ok());
  EXPECT_FALSE(first.cached());
  EXPECT_TRUE(second.cached());
  EXPECT_EQ(second.correlation(), first.correlation());
  EXPECT_EQ(second.step_count(), first.step_count());
  // Another option is another request.
  request.mutable_goal()->mutable_options()->set_max_height_mm(20.0);
  ASSERT_TRUE(s.planning->Preview(call().get(), request, &other).ok());
  EXPECT_FALSE(other.cached());
  EXPECT_EQ(s.server->cache().size(), 2);
}

TEST(ServerPlanning, CancellingFreesTheWorker) {
  ScratchDir dir;
  TestServer s(options(1, 1, dir.path / "q.db"), false);
  auto context = call();
  auto reader = s.planning->Plan(context.get(), endless_request());
  wait_until_running(*reader);
  context->TryCancel();
  EXPECT_EQ(reader->Finish().error_code(), StatusCode::CANCELLED);
  // The only worker serves the next request (it would wait forever behind an endless plan).
  v1::PreviewResponse response;
  const grpc::Status next = s.planning->Preview(call("", 30).get(), preview_request(2, 2), &response);
  EXPECT_TRUE(next.ok()) << next.error_message();
}

TEST(ServerPlanning, ADeadlineStopsThePlanAndFreesTheWorker) {
  ScratchDir dir;
  TestServer s(options(1, 1, dir.path / "q.db"), false);
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() + std::chrono::milliseconds(300));
  v1::PreviewRequest request = preview_request(2, 2);
  request.set_planner("test-endless");
  v1::PreviewResponse response;
  EXPECT_EQ(s.planning->Preview(&context, request, &response).error_code(), StatusCode::DEADLINE_EXCEEDED);
  const grpc::Status next = s.planning->Preview(call("", 30).get(), preview_request(2, 2), &response);
  EXPECT_TRUE(next.ok()) << next.error_message();
}

TEST(ServerPlanning, AFullQueueIsRefusedAtOnce) {
  ScratchDir dir;
  TestServer s(options(1, 1, dir.path / "q.db"), false);
  auto running_context = call();
  auto running = s.planning->Plan(running_context.get(), endless_request());
  wait_until_running(*running);
  // A second request waits for the worker...
  auto waiting_context = call();
  auto waiting = s.planning->Plan(waiting_context.get(), endless_request());
  ASSERT_TRUE(eventually([&] { return s.server->pool().waiting() == 1; }));
  // ...and a third finds the queue full.
  v1::PreviewResponse response;
  v1::PreviewRequest third = preview_request(2, 2);
  const grpc::Status refused = s.planning->Preview(call().get(), third, &response);
  EXPECT_EQ(refused.error_code(), StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_NE(refused.error_message().find("queue full"), std::string::npos) << refused.error_message();
  running_context->TryCancel();
  waiting_context->TryCancel();
  running->Finish();
  waiting->Finish();
}

void expect_refused(TestServer& s, const v1::PreviewRequest& request, StatusCode code,
                    const std::vector<std::string>& words) {
  v1::PreviewResponse response;
  const grpc::Status status = s.planning->Preview(call().get(), request, &response);
  EXPECT_EQ(status.error_code(), code) << status.error_message();
  for (const auto& w : words)
    EXPECT_NE(status.error_message().find(w), std::string::npos) << "\"" << w << "\" not in: " << status.error_message();
}

TEST(ServerPlanning, BadRequestsAreRefusedNamingWhatIsWrong) {
  ScratchDir dir;
  TestServer s(options(1, 4, dir.path / "q.db"), false);
  expect_refused(s, preview_request(2, 2, "1,2,x\n3,4\n"), StatusCode::INVALID_ARGUMENT, {"bump.csv"});
  v1::PreviewRequest no_goal = preview_request(2, 2);
  no_goal.clear_goal();
  expect_refused(s, no_goal, StatusCode::INVALID_ARGUMENT, {"goal"});
  expect_refused(s, preview_request(65, 2), StatusCode::INVALID_ARGUMENT, {"array.rows", "65", "limit of 64"});
  v1::PreviewRequest big_mesh = preview_request(64, 64);
  big_mesh.mutable_array()->set_segments(16);
  expect_refused(s, big_mesh, StatusCode::INVALID_ARGUMENT, {"mesh points", "limit"});
  v1::PreviewRequest planner = preview_request(2, 2);
  planner.set_planner("nope");
  expect_refused(s, planner, StatusCode::INVALID_ARGUMENT, {"unknown planner", "nope", "algorithm2"});
  v1::PreviewRequest map = preview_request(2, 2);
  map.mutable_goal()->set_map_name("alps");
  expect_refused(s, map, StatusCode::INVALID_ARGUMENT, {"alps", "not a map"});
  v1::PreviewRequest axis = preview_request(2, 2);
  axis.mutable_goal()->mutable_options()->set_up_axis("w");
  expect_refused(s, axis, StatusCode::INVALID_ARGUMENT, {"up_axis"});
  v1::PreviewRequest effect = preview_request(2, 2);
  effect.mutable_array()->mutable_parameters()->add_effects()->set_name("no-such-effect");
  expect_refused(s, effect, StatusCode::INVALID_ARGUMENT, {"no-such-effect"});
  v1::PreviewRequest region = preview_request(2, 2);
  region.mutable_goal()->mutable_region()->set_x1(2.0);
  expect_refused(s, region, StatusCode::INVALID_ARGUMENT, {"region"});
}

TEST(ServerPlanning, AGoalOverTheMessageLimitIsRefusedNamingTheLimit) {
  ScratchDir dir;
  server::ServerOptions o = options(1, 4, dir.path / "q.db");
  o.limits.max_message_bytes = 1 << 20;
  TestServer s(o, false);
  expect_refused(s, preview_request(2, 2, std::string(2 << 20, '1')), StatusCode::RESOURCE_EXHAUSTED,
                 {"larger than max"});
}

TEST(ServerPlanning, AGoalWithTooManyPixelsIsRefusedNamingTheLimit) {
  ScratchDir dir;
  server::ServerOptions o = options(1, 4, dir.path / "q.db");
  o.limits.max_goal_pixels = 100;
  TestServer s(o, false);
  expect_refused(s, preview_request(2, 2, bump_csv(16, 20)), StatusCode::INVALID_ARGUMENT,
                 {"bump.csv", "more than 100 values"});
}

TEST(ServerPlanning, MapsAreCroppedToTheRequestedRegion) {
  ScratchDir dir;
  server::ServerOptions o = options(1, 4, dir.path / "q.db");
  o.maps = {{"volcano", HJ_SHARED_DIR "/data/dem/volcano_maunga_whau.csv"}};
  TestServer s(o, false);
  v1::ListPlannersResponse list;
  ASSERT_TRUE(s.planning->ListPlanners(call().get(), {}, &list).ok());
  ASSERT_EQ(list.maps_size(), 1);
  EXPECT_EQ(list.maps(0), "volcano");
  v1::PreviewRequest whole = preview_request(2, 2), quarter = preview_request(2, 2);
  whole.mutable_goal()->set_map_name("volcano");
  quarter.mutable_goal()->set_map_name("volcano");
  auto* r = quarter.mutable_goal()->mutable_region();
  r->set_x1(0.5), r->set_y1(0.5);
  v1::PreviewResponse a, b;
  ASSERT_TRUE(s.planning->Preview(call().get(), whole, &a).ok());
  ASSERT_TRUE(s.planning->Preview(call().get(), quarter, &b).ok());
  // A different part of the map is a different goal on the mesh.
  EXPECT_NE(a.goal_heights_mm(7), b.goal_heights_mm(7));
  EXPECT_FALSE(b.cached());
}

}  // namespace
}  // namespace hj
