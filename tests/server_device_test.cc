// DeviceService over gRPC against an in-process server with a fake device
// link: order and positions of two callers' jobs, a link drop mid-job, an
// emergency stop, a restart on the same database, roles and bad plans.
#include <gtest/gtest.h>

#include <grpcpp/generic/generic_stub.h>
#include <grpcpp/impl/codegen/client_unary_call.h>

#include "expect_error.h"
#include "server_fixture.h"

namespace hj {
namespace {

using namespace testing_support;
using grpc::StatusCode;

// alice and bob operate, carol previews, root administers.
struct AuthServer {
  explicit AuthServer(const std::filesystem::path& dir, std::string db_name = "q.db") {
    std::ofstream(dir / "auth.txt") << "# name role token\n"
                                       "alice operator alice-token-1\n"
                                       "bob operator bob-token-22\n"
                                       "carol preview carol-token-3\n"
                                       "root admin root-token-444\n";
    options.auth_file = (dir / "auth.txt").string();
    options.db_file = (dir / db_name).string();
    options.workers = 1;
  }
  server::ServerOptions options;
};

v1::Job submit(TestServer& s, const std::string& token, const v1::Plan& plan, grpc::Status* status = nullptr) {
  v1::SubmitJobRequest request;
  *request.mutable_plan() = plan;
  v1::SubmitJobResponse response;
  const grpc::Status st = s.device->SubmitJob(call(token).get(), request, &response);
  if (status) *status = st;
  else EXPECT_TRUE(st.ok()) << st.error_message();
  return response.job();
}

v1::Job get_job(TestServer& s, std::int64_t id) {
  v1::GetJobRequest request;
  request.set_id(id);
  v1::Job job;
  const grpc::Status st = s.device->GetJob(call("root-token-444").get(), request, &job);
  EXPECT_TRUE(st.ok()) << st.error_message();
  return job;
}

v1::QueueState queue(TestServer& s, const std::string& token = "root-token-444") {
  v1::WatchQueueRequest request;
  request.set_recent_finished(10);
  auto context = call(token);
  auto reader = s.device->WatchQueue(context.get(), request);
  v1::QueueState state;
  EXPECT_TRUE(reader->Read(&state));
  context->TryCancel();
  reader->Finish();
  return state;
}

bool job_state_is(TestServer& s, std::int64_t id, v1::JobState state) { return get_job(s, id).state() == state; }

const v1::Plan kThreeSteps = device_plan({"p 0.3", "j 0 1", "c"});

TEST(ServerDevice, TwoCallersJobsRunInOrderAndEachSeesTheOthersAhead) {
  ScratchDir dir;
  AuthServer auth(dir.path);
  TestServer s(auth.options);
  s.link->hold();
  const v1::Job a1 = submit(s, "alice-token-1", kThreeSteps);
  ASSERT_TRUE(eventually([&] { return s.link->waiting() == 1; }));  // a1 runs, held at its first step
  const v1::Job b1 = submit(s, "bob-token-22", device_plan({"p 0.5"}));
  const v1::Job a2 = submit(s, "alice-token-1", device_plan({"p 0.7"}));
  EXPECT_EQ(b1.position(), 1);
  EXPECT_EQ(a2.position(), 2);

  // Bob's view: alice's running job first, his next, alice's second after it.
  const v1::QueueState seen_by_bob = queue(s, "bob-token-22");
  ASSERT_GE(seen_by_bob.jobs_size(), 3);
  EXPECT_EQ(seen_by_bob.jobs(0).id(), a1.id());
  EXPECT_EQ(seen_by_bob.jobs(0).owner(), "alice");
  EXPECT_EQ(seen_by_bob.jobs(0).state(), v1::JOB_STATE_RUNNING);
  EXPECT_EQ(seen_by_bob.jobs(0).position(), 0);
  EXPECT_EQ(seen_by_bob.jobs(1).id(), b1.id());
  EXPECT_EQ(seen_by_bob.jobs(1).owner(), "bob");
  EXPECT_EQ(seen_by_bob.jobs(2).id(), a2.id());

  s.link->free_run();
  ASSERT_TRUE(eventually([&] { return job_state_is(s, a2.id(), v1::JOB_STATE_DONE); }));
  EXPECT_EQ(get_job(s, a1.id()).state(), v1::JOB_STATE_DONE);
  EXPECT_EQ(get_job(s, b1.id()).state(), v1::JOB_STATE_DONE);
  // Each job from the rest state, in submission order.
  const std::vector<std::string> expected = {"vent",    "vent", Action::set_pressure(300).describe(),
                                             Action::jam(0, 1).describe(), "capture",
                                             "vent",    Action::set_pressure(500).describe(),
                                             "vent",    Action::set_pressure(700).describe()};
  EXPECT_EQ(s.link->log(), expected);
  const v1::Job done = get_job(s, a1.id());
  EXPECT_EQ(done.steps_done(), 3);
  ASSERT_EQ(done.captures_size(), 1);
  EXPECT_EQ(done.captures(0).step_index(), 2);
  EXPECT_EQ(done.captures(0).grid().nx(), 3);
  EXPECT_EQ(done.captures(0).heights_mm_size(), 6);
  EXPECT_DOUBLE_EQ(done.captures(0).heights_mm(0), 3.0);  // the fake reports pressure / 100
}

TEST(ServerDevice, ALinkDropInterruptsTheJobPausesTheQueueAndVentsOnReconnect) {
  ScratchDir dir;
  AuthServer auth(dir.path);
  TestServer s(auth.options);
  s.link->hold();
  const v1::Job first = submit(s, "alice-token-1", kThreeSteps);
  const v1::Job second = submit(s, "bob-token-22", device_plan({"p 0.4"}));
  ASSERT_TRUE(eventually([&] { return s.link->waiting() == 1; }));

  // A watcher hears of the interruption from the drop itself.
  auto watch_context = call("carol-token-3");
  auto watcher = s.device->WatchQueue(watch_context.get(), {});
  v1::QueueState state;
  ASSERT_TRUE(watcher->Read(&state));
  s.link->set_connected(false);
  bool told = false;
  while (!told && watcher->Read(&state)) told = state.paused() && !state.device_connected();
  ASSERT_TRUE(told);
  watch_context->TryCancel();
  watcher->Finish();
  EXPECT_EQ(get_job(s, first.id()).state(), v1::JOB_STATE_INTERRUPTED);
  EXPECT_NE(get_job(s, first.id()).error().find("link dropped"), std::string::npos);

  // Offline: nothing can be submitted.
  grpc::Status status;
  submit(s, "alice-token-1", device_plan({"p 0.1"}), &status);
  EXPECT_EQ(status.error_code(), StatusCode::FAILED_PRECONDITION);
  EXPECT_NE(status.error_message().find("offline"), std::string::npos) << status.error_message();

  // Back: vented first, and the next job does not start on its own.
  const int vents = s.link->vents();
  s.link->free_run();
  s.link->set_connected(true);
  ASSERT_TRUE(eventually([&] { return s.link->vents() > vents; }));
  const v1::QueueState paused = queue(s);
  EXPECT_TRUE(paused.paused());
  EXPECT_NE(paused.pause_reason().find("interrupted"), std::string::npos) << paused.pause_reason();
  EXPECT_EQ(get_job(s, second.id()).state(), v1::JOB_STATE_QUEUED);
  submit(s, "alice-token-1", device_plan({"p 0.1"}), &status);
  EXPECT_EQ(status.error_code(), StatusCode::FAILED_PRECONDITION);

  // An operator resumes it (a previewer may not); then the queued job runs.
  v1::QueueState resumed;
  EXPECT_EQ(s.device->ResumeQueue(call("carol-token-3").get(), {}, &resumed).error_code(),
            StatusCode::PERMISSION_DENIED);
  ASSERT_TRUE(s.device->ResumeQueue(call("alice-token-1").get(), {}, &resumed).ok());
  EXPECT_FALSE(resumed.paused());
  ASSERT_TRUE(eventually([&] { return job_state_is(s, second.id(), v1::JOB_STATE_DONE); }));
}

TEST(ServerDevice, EmergencyStopVentsAtOnceAndPauses) {
  ScratchDir dir;
  AuthServer auth(dir.path);
  TestServer s(auth.options);
  s.link->hold();
  const v1::Job job = submit(s, "alice-token-1", kThreeSteps);
  ASSERT_TRUE(eventually([&] { return s.link->waiting() == 1; }));
  const int vents = s.link->vents();
  v1::EmergencyStopRequest request;
  request.set_reason("hand on the surface");
  v1::DeviceStatus status;
  EXPECT_EQ(s.device->EmergencyStop(call("carol-token-3").get(), request, &status).error_code(),
            StatusCode::PERMISSION_DENIED);
  ASSERT_TRUE(s.device->EmergencyStop(call("root-token-444").get(), request, &status).ok());
  // Vented while the job's step was still held: the stop did not wait for the queue.
  EXPECT_EQ(s.link->vents(), vents + 1);
  EXPECT_EQ(s.link->waiting(), 1);
  EXPECT_TRUE(status.emergency_stopped());
  EXPECT_TRUE(status.queue_paused());
  EXPECT_NE(status.pause_reason().find("hand on the surface"), std::string::npos);
  const v1::Job stopped = get_job(s, job.id());
  EXPECT_EQ(stopped.state(), v1::JOB_STATE_INTERRUPTED);
  EXPECT_NE(stopped.error().find("emergency stop by root"), std::string::npos) << stopped.error();
  grpc::Status refused;
  submit(s, "alice-token-1", device_plan({"p 0.1"}), &refused);
  EXPECT_EQ(refused.error_code(), StatusCode::FAILED_PRECONDITION);
  s.link->free_run();
}

// A role that cannot stop the array cannot clear a stop: operators do both, previewers neither.
TEST(ServerDevice, WhoMayStopMayResumeAndNoOneElse) {
  ScratchDir dir;
  AuthServer auth(dir.path);
  TestServer s(auth.options);
  ASSERT_TRUE(eventually([&] { return queue(s).device_connected(); }));
  v1::EmergencyStopRequest request;
  v1::DeviceStatus status;
  v1::QueueState resumed;
  EXPECT_EQ(s.device->EmergencyStop(call("carol-token-3").get(), request, &status).error_code(),
            StatusCode::PERMISSION_DENIED);
  ASSERT_TRUE(s.device->EmergencyStop(call("bob-token-22").get(), request, &status).ok());
  EXPECT_TRUE(status.emergency_stopped());
  const grpc::Status denied = s.device->ResumeQueue(call("carol-token-3").get(), {}, &resumed);
  EXPECT_EQ(denied.error_code(), StatusCode::PERMISSION_DENIED);
  EXPECT_NE(denied.error_message().find("operator"), std::string::npos) << denied.error_message();
  EXPECT_TRUE(queue(s).paused());
  ASSERT_TRUE(s.device->ResumeQueue(call("bob-token-22").get(), {}, &resumed).ok());
  EXPECT_FALSE(resumed.paused());
  // The halt is cleared with the stop: a job runs again.
  const v1::Job job = submit(s, "alice-token-1", device_plan({"p 0.2"}));
  ASSERT_TRUE(eventually([&] { return job_state_is(s, job.id(), v1::JOB_STATE_DONE); }));
}

TEST(ServerDevice, ARestartOnTheSameDatabaseKeepsTheQueueAndReportsTheRunningJobInterrupted) {
  ScratchDir dir;
  AuthServer auth(dir.path);
  std::int64_t running_id = 0, queued_id = 0;
  {
    TestServer s(auth.options);
    s.link->hold();
    running_id = submit(s, "alice-token-1", kThreeSteps).id();
    queued_id = submit(s, "bob-token-22", device_plan({"p 0.4", "c"})).id();
    ASSERT_TRUE(eventually([&] { return s.link->waiting() == 1; }));
    s.server->shutdown();  // as far as the queue can tell, a crash mid-job
  }
  TestServer s(auth.options);
  const v1::Job interrupted = get_job(s, running_id);
  EXPECT_EQ(interrupted.state(), v1::JOB_STATE_INTERRUPTED);
  EXPECT_EQ(interrupted.owner(), "alice");
  EXPECT_NE(interrupted.error().find("server stopped"), std::string::npos) << interrupted.error();
  const v1::Job kept = get_job(s, queued_id);
  EXPECT_EQ(kept.state(), v1::JOB_STATE_QUEUED);
  EXPECT_EQ(kept.owner(), "bob");
  EXPECT_EQ(kept.steps_total(), 2);
  EXPECT_EQ(kept.position(), 1);
  const v1::QueueState state = queue(s);
  EXPECT_TRUE(state.paused());
  // Resumed by an admin, the kept job runs.
  v1::QueueState resumed;
  ASSERT_TRUE(s.device->ResumeQueue(call("root-token-444").get(), {}, &resumed).ok());
  ASSERT_TRUE(eventually([&] { return job_state_is(s, queued_id, v1::JOB_STATE_DONE); }));
  EXPECT_EQ(get_job(s, queued_id).captures_size(), 1);
}

TEST(ServerDevice, CallersAreCheckedAndBadPlansRefusedWithoutLosingQueuedJobs) {
  ScratchDir dir;
  AuthServer auth(dir.path);
  TestServer s(auth.options);
  s.link->hold();
  const v1::Job kept = submit(s, "alice-token-1", kThreeSteps);
  const v1::Job waiting = submit(s, "alice-token-1", device_plan({"p 0.2"}));

  auto expect = [&](const std::string& token, const v1::Plan& plan, StatusCode code, const std::vector<std::string>& words) {
    grpc::Status status;
    submit(s, token, plan, &status);
    EXPECT_EQ(status.error_code(), code) << status.error_message();
    for (const auto& w : words)
      EXPECT_NE(status.error_message().find(w), std::string::npos) << "\"" << w << "\" not in: " << status.error_message();
  };
  expect("", kThreeSteps, StatusCode::UNAUTHENTICATED, {"bearer token"});
  expect("not-a-token", kThreeSteps, StatusCode::UNAUTHENTICATED, {"unknown"});
  expect("carol-token-3", kThreeSteps, StatusCode::PERMISSION_DENIED, {"carol", "preview", "operator"});
  expect("alice-token-1", device_plan({"p 0.3", "p 9.0"}), StatusCode::INVALID_ARGUMENT, {"step 1", "pressure"});
  expect("alice-token-1", device_plan({"j 3 0"}), StatusCode::INVALID_ARGUMENT, {"step 0", "3"});
  expect("alice-token-1", device_plan({"n 0 1"}), StatusCode::INVALID_ARGUMENT, {"step 0"});
  expect("alice-token-1", v1::Plan(), StatusCode::INVALID_ARGUMENT, {"no steps"});
  v1::Plan no_op;
  no_op.add_steps();
  expect("alice-token-1", no_op, StatusCode::INVALID_ARGUMENT, {"step 0", "no op"});

  // Bob may not cancel alice's job; alice may; an admin may cancel anyone's.
  v1::CancelJobRequest cancel;
  cancel.set_id(waiting.id());
  v1::CancelJobResponse response;
  EXPECT_EQ(s.device->CancelJob(call("bob-token-22").get(), cancel, &response).error_code(),
            StatusCode::PERMISSION_DENIED);
  ASSERT_TRUE(s.device->CancelJob(call("alice-token-1").get(), cancel, &response).ok());
  EXPECT_EQ(response.job().state(), v1::JOB_STATE_CANCELLED);
  EXPECT_EQ(s.device->CancelJob(call("alice-token-1").get(), cancel, &response).error_code(),
            StatusCode::FAILED_PRECONDITION);

  // Nothing refused disturbed the job already queued.
  const v1::QueueState state = queue(s);
  ASSERT_GE(state.jobs_size(), 1);
  EXPECT_EQ(state.jobs(0).id(), kept.id());
  EXPECT_EQ(state.jobs(0).state(), v1::JOB_STATE_RUNNING);
  cancel.set_id(kept.id());
  ASSERT_TRUE(s.device->CancelJob(call("root-token-444").get(), cancel, &response).ok());
  s.link->free_run();
  ASSERT_TRUE(eventually([&] { return s.link->waiting() == 0 && queue(s).jobs(0).state() != v1::JOB_STATE_RUNNING; }));
  EXPECT_EQ(get_job(s, kept.id()).state(), v1::JOB_STATE_CANCELLED);
}

TEST(ServerDevice, PlanningNeedsAKnownCallerToo) {
  ScratchDir dir;
  AuthServer auth(dir.path);
  TestServer s(auth.options);
  v1::PreviewResponse response;
  EXPECT_EQ(s.planning->Preview(call("").get(), preview_request(2, 2), &response).error_code(),
            StatusCode::UNAUTHENTICATED);
  const grpc::Status ok = s.planning->Preview(call("carol-token-3").get(), preview_request(2, 2), &response);
  EXPECT_TRUE(ok.ok()) << ok.error_message();
}

// grpc.health.v1.Health/Check by hand: HealthCheckRequest{service = 1} and
// HealthCheckResponse{status = 1}, SERVING = 1, NOT_SERVING = 2.
int health(TestServer& s, const std::string& service) {
  std::string request = "\x0a" + std::string(1, char(service.size())) + service;
  grpc::Slice slice(request);
  grpc::ByteBuffer in(&slice, 1), out;
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(10));
  const grpc::Status status = grpc::internal::BlockingUnaryCall<grpc::ByteBuffer, grpc::ByteBuffer>(
      s.channel.get(), grpc::internal::RpcMethod("/grpc.health.v1.Health/Check", grpc::internal::RpcMethod::NORMAL_RPC),
      &context, in, &out);
  if (!status.ok()) return -int(status.error_code());
  std::vector<grpc::Slice> slices;
  out.Dump(&slices);
  std::string bytes;
  for (const auto& sl : slices) bytes.append(reinterpret_cast<const char*>(sl.begin()), sl.size());
  return bytes.size() == 2 && bytes[0] == 0x08 ? bytes[1] : 0;
}

TEST(ServerDevice, HealthFollowsTheDeviceLink) {
  ScratchDir dir;
  server::ServerOptions o;
  o.db_file = (dir.path / "q.db").string();
  TestServer s(o);
  EXPECT_EQ(health(s, "hapticjam.v1.PlanningService"), 1);
  EXPECT_TRUE(eventually([&] { return health(s, "hapticjam.v1.DeviceService") == 1; }));
  s.link->set_connected(false);
  EXPECT_EQ(health(s, "hapticjam.v1.DeviceService"), 2);
  EXPECT_EQ(health(s, "hapticjam.v1.PlanningService"), 1);
}

TEST(ServerOptions, WithoutAuthOnlyLoopbackIsAllowed) {
  bool help = false;
  EXPECT_THROW(server::parse_server_args({"--listen", "0.0.0.0:7000"}, &help), std::invalid_argument);
  // Tokens never cross a network in the clear unless the operator says it is private.
  testing_support::expect_error<std::invalid_argument>(
      [&] { server::parse_server_args({"--listen", "0.0.0.0:7000", "--auth", "a.txt"}, &help); },
      {"--listen 0.0.0.0:7000", "in the clear", "--trusted-network"});
  EXPECT_NO_THROW(server::parse_server_args({"--listen", "0.0.0.0:7000", "--auth", "a.txt", "--trusted-network"}, &help));
  EXPECT_NO_THROW(server::parse_server_args(
      {"--listen", "0.0.0.0:7000", "--auth", "a.txt", "--tls-cert", "c.pem", "--tls-key", "k.pem"}, &help));
  EXPECT_NO_THROW(server::parse_server_args({"--listen", "[::1]:7000"}, &help));
  EXPECT_THROW(server::parse_server_args({"--listen", "127.0.0.1:1", "--tls-cert", "c.pem"}, &help),
               std::invalid_argument);
  EXPECT_THROW(server::parse_server_args({"--listen", "127.0.0.1:1", "--workers", "0"}, &help), std::invalid_argument);
  server::parse_server_args({"--help"}, &help);
  EXPECT_TRUE(help);
}

TEST(ServerOptions, AuthFileErrorsNameTheLine) {
  ScratchDir dir;
  std::ofstream(dir.path / "bad.txt") << "alice operator alice-token-1\nbob superuser bob-token-22\n";
  try {
    server::Authenticator::from_file(dir.path / "bad.txt");
    ADD_FAILURE() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("line 2"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("superuser"), std::string::npos) << e.what();
  }
}

TEST(ServerOptions, ATokenFileOthersCanReadIsWarnedAbout) {
  ScratchDir dir;
  const auto file = dir.path / "auth.txt";
  std::ofstream(file) << "alice operator alice-token-1\n";
  std::filesystem::permissions(file, std::filesystem::perms::owner_read | std::filesystem::perms::owner_write);
  EXPECT_TRUE(server::Authenticator::from_file(file).warnings().empty());
  std::filesystem::permissions(file, std::filesystem::perms::others_read, std::filesystem::perm_options::add);
  const auto warnings = server::Authenticator::from_file(file).warnings();
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("readable by other users"), std::string::npos) << warnings[0];
}

}  // namespace
}  // namespace hj
