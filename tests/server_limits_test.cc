// The limits an operator sets on each call (server_limits.h): their flags,
// a plan past --max-plan-seconds ends DEADLINE_EXCEEDED and frees its worker,
// calibration threads are capped, job names and queue watchers are bounded,
// and with TLS and auth a call without a known token is refused before its
// message is parsed.
#include <gtest/gtest.h>

#include <grpcpp/impl/codegen/client_unary_call.h>
#include <grpcpp/impl/codegen/rpc_method.h>
#include <grpcpp/support/byte_buffer.h>

#include <fstream>

#include "expect_error.h"
#include "server_fixture.h"
#include "server_options.h"
#include "tls_fixture.h"

namespace hj {
namespace {

using namespace testing_support;
using grpc::StatusCode;

server::ServerOptions options(int workers, int queue_size, const std::filesystem::path& db) {
  server::ServerOptions o;
  o.workers = workers;
  o.queue_size = queue_size;
  o.db_file = db.string();
  return o;
}

server::ServerOptions parse(std::vector<std::string> args) {
  args.insert(args.begin(), {"--listen", "127.0.0.1:0"});
  bool help = false;
  return server::parse_server_args(args, &help);
}

TEST(ServerLimits, TheFlagsSetTheLimits) {
  const server::ServerOptions o =
      parse({"--max-plan-seconds", "5", "--max-calibration-seconds", "0", "--calibration-threads", "2",
             "--max-job-name-bytes", "40", "--max-watchers", "3", "--max-threads", "64", "--max-streams", "10",
             "--keepalive-seconds", "30"});
  EXPECT_EQ(o.limits.max_plan_time, std::chrono::seconds(5));
  EXPECT_EQ(o.limits.max_calibration_time, std::chrono::seconds(0));
  EXPECT_EQ(o.limits.calibration_threads, 2);
  EXPECT_EQ(o.limits.max_job_name_bytes, 40);
  EXPECT_EQ(o.limits.max_watchers, 3);
  EXPECT_EQ(o.limits.max_threads, 64);
  EXPECT_EQ(o.limits.max_concurrent_streams, 10);
  EXPECT_EQ(o.limits.keepalive_time, std::chrono::seconds(30));
  expect_error<std::invalid_argument>([] { parse({"--max-watchers", "0"}); }, {"--max-watchers", "[1, "});
  expect_error<std::invalid_argument>([] { parse({"--keepalive-seconds", "1"}); }, {"--keepalive-seconds"});
  expect_error<std::invalid_argument>([] { parse({"--max-plan-seconds", "soon"}); }, {"--max-plan-seconds", "soon"});
}

TEST(ServerLimits, ACalibrationTakesAtMostTheOperatorsCores) {
  server::ServerLimits limits;
  EXPECT_EQ(server::calibration_thread_count(0, limits, 8), 8);  // no limit: every core
  EXPECT_EQ(server::calibration_thread_count(3, limits, 8), 3);
  EXPECT_EQ(server::calibration_thread_count(99, limits, 8), 8);
  limits.calibration_threads = 2;
  EXPECT_EQ(server::calibration_thread_count(0, limits, 8), 2);
  EXPECT_EQ(server::calibration_thread_count(5, limits, 8), 2);
  EXPECT_EQ(server::calibration_thread_count(1, limits, 8), 1);
  EXPECT_EQ(server::calibration_thread_count(0, limits, 1), 1);  // never more than the machine has
}

TEST(ServerLimits, APlanPastTheServersLimitEndsDeadlineExceededAndFreesTheWorker) {
  ScratchDir dir;
  server::ServerOptions o = options(1, 0, dir.path / "q.db");
  o.limits.max_plan_time = std::chrono::milliseconds(300);
  TestServer s(o, false);
  v1::PlanRequest request = plan_request(2, 2);
  request.set_planner("test-endless");
  auto context = call("", 60);  // the caller would wait a minute
  auto reader = s.planning->Plan(context.get(), request);
  for (v1::PlanEvent event; reader->Read(&event);) {
  }
  const grpc::Status status = reader->Finish();
  EXPECT_EQ(status.error_code(), StatusCode::DEADLINE_EXCEEDED) << status.error_message();
  EXPECT_NE(status.error_message().find("--max-plan-seconds"), std::string::npos) << status.error_message();
  // The only worker, with no queue, takes the next request once the endless plan has stopped.
  v1::PreviewResponse response;
  EXPECT_TRUE(eventually([&] {
    return s.planning->Preview(call("", 30).get(), preview_request(2, 2), &response).error_code() !=
           StatusCode::RESOURCE_EXHAUSTED;
  }));
}

v1::SubmitJobRequest named_job(const std::string& name) {
  v1::SubmitJobRequest request;
  request.set_name(name);
  *request.mutable_plan() = device_plan({"p 0.3"});
  return request;
}

TEST(ServerLimits, AJobNameIsBoundedAndHasNoControlCharacters) {
  ScratchDir dir;
  server::ServerOptions o = options(1, 1, dir.path / "q.db");
  o.limits.max_job_name_bytes = 10;
  TestServer s(o);
  v1::SubmitJobResponse response;
  const grpc::Status long_name = s.device->SubmitJob(call().get(), named_job(std::string(11, 'x')), &response);
  EXPECT_EQ(long_name.error_code(), StatusCode::INVALID_ARGUMENT);
  EXPECT_NE(long_name.error_message().find("--max-job-name-bytes"), std::string::npos) << long_name.error_message();
  const grpc::Status control = s.device->SubmitJob(call().get(), named_job("a\nb"), &response);
  EXPECT_EQ(control.error_code(), StatusCode::INVALID_ARGUMENT);
  EXPECT_NE(control.error_message().find("control character at byte 1"), std::string::npos)
      << control.error_message();
  ASSERT_TRUE(eventually([&] { return s.device->SubmitJob(call().get(), named_job("ten bytes!"), &response).ok(); }));
  EXPECT_EQ(response.job().name(), "ten bytes!");
}

TEST(ServerLimits, AFullDeviceQueueRefusesNamingItsFlagAndKeepsWhatWaits) {
  ScratchDir dir;
  server::ServerOptions o = options(1, 1, dir.path / "q.db");
  o.device_queue_size = 1;
  TestServer s(o);
  s.link->hold();
  v1::SubmitJobResponse running, waiting, refused_response;
  ASSERT_TRUE(eventually([&] { return s.device->SubmitJob(call().get(), named_job("one"), &running).ok(); }));
  ASSERT_TRUE(eventually([&] { return s.link->waiting() == 1; }));  // "one" runs, held at its step
  ASSERT_TRUE(s.device->SubmitJob(call().get(), named_job("two"), &waiting).ok());
  const grpc::Status refused = s.device->SubmitJob(call().get(), named_job("three"), &refused_response);
  EXPECT_EQ(refused.error_code(), StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_NE(refused.error_message().find("--device-queue-size"), std::string::npos) << refused.error_message();
  v1::GetJobRequest get;
  get.set_id(waiting.job().id());
  v1::Job job;
  ASSERT_TRUE(s.device->GetJob(call().get(), get, &job).ok());
  EXPECT_EQ(job.state(), v1::JOB_STATE_QUEUED);
  s.link->release();
}

TEST(ServerLimits, QueueWatchersAreBounded) {
  ScratchDir dir;
  server::ServerOptions o = options(1, 1, dir.path / "q.db");
  o.limits.max_watchers = 2;
  TestServer s(o);
  std::vector<std::unique_ptr<grpc::ClientContext>> contexts;
  std::vector<std::unique_ptr<grpc::ClientReader<v1::QueueState>>> readers;
  for (int k = 0; k < 2; ++k) {
    contexts.push_back(call());
    readers.push_back(s.device->WatchQueue(contexts.back().get(), v1::WatchQueueRequest()));
    v1::QueueState state;
    ASSERT_TRUE(readers.back()->Read(&state)) << "watcher " << k;
  }
  auto third_context = call();
  auto third = s.device->WatchQueue(third_context.get(), v1::WatchQueueRequest());
  v1::QueueState state;
  EXPECT_FALSE(third->Read(&state));
  const grpc::Status refused = third->Finish();
  EXPECT_EQ(refused.error_code(), StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_NE(refused.error_message().find("--max-watchers"), std::string::npos) << refused.error_message();

  // A watcher that leaves frees its slot.
  contexts[0]->TryCancel();
  readers[0]->Finish();
  EXPECT_TRUE(eventually([&] {
    auto context = call();
    auto reader = s.device->WatchQueue(context.get(), v1::WatchQueueRequest());
    v1::QueueState first;
    const bool read = reader->Read(&first);
    context->TryCancel();
    reader->Finish();
    return read;
  }));
  for (size_t k = 1; k < readers.size(); ++k) {
    contexts[k]->TryCancel();
    readers[k]->Finish();
  }
}

TEST(ServerLimits, AWatcherMayListABoundedNumberOfFinishedJobs) {
  ScratchDir dir;
  TestServer s(options(1, 1, dir.path / "q.db"));
  for (int asked : {-1, 1'000'000}) {
    v1::WatchQueueRequest request;
    request.set_recent_finished(asked);
    auto context = call();
    auto reader = s.device->WatchQueue(context.get(), request);
    v1::QueueState state;
    EXPECT_FALSE(reader->Read(&state));
    const grpc::Status status = reader->Finish();
    EXPECT_EQ(status.error_code(), StatusCode::INVALID_ARGUMENT) << asked;
    EXPECT_NE(status.error_message().find("recent_finished = " + std::to_string(asked)), std::string::npos)
        << status.error_message();
  }
}

// A unary call with raw bytes as its request, as a hostile client could send.
grpc::Status raw_call(grpc::Channel& channel, const std::string& method, const std::string& bytes,
                      const std::string& token) {
  const grpc::internal::RpcMethod rpc(method.c_str(), grpc::internal::RpcMethod::NORMAL_RPC);
  grpc::Slice slice(bytes);
  grpc::ByteBuffer request(&slice, 1), response;
  return grpc::internal::BlockingUnaryCall(&channel, rpc, call(token, 30).get(), request, &response);
}

TEST(ServerLimits, WithTlsAnUnknownCallerIsRefusedBeforeTheMessageIsParsed) {
  ScratchDir dir;
  std::ofstream(dir.path / "auth.txt") << "alice operator alice-token-1\n";
  std::ofstream(dir.path / "cert.pem") << kTestTlsCert;
  std::ofstream(dir.path / "key.pem") << kTestTlsKey;
  server::ServerOptions o = options(1, 1, dir.path / "q.db");
  o.auth_file = (dir.path / "auth.txt").string();
  o.tls_cert = (dir.path / "cert.pem").string();
  o.tls_key = (dir.path / "key.pem").string();
  TestServer s(o, false);
  grpc::SslCredentialsOptions ssl;
  ssl.pem_root_certs = kTestTlsCert;
  auto channel = grpc::CreateChannel("127.0.0.1:" + std::to_string(s.server->port()), grpc::SslCredentials(ssl));

  // Bytes that are no PreviewRequest: a known caller gets the parse error,
  // anyone else UNAUTHENTICATED, decided from the headers alone.
  const std::string garbage = "\xff\xff\xff\xff\xff\xff";
  const std::string preview = "/hapticjam.v1.PlanningService/Preview";
  const grpc::Status known = raw_call(*channel, preview, garbage, "alice-token-1");
  EXPECT_NE(known.error_code(), StatusCode::UNAUTHENTICATED) << known.error_message();
  EXPECT_NE(known.error_code(), StatusCode::OK);
  for (const std::string token : {"", "mallory-token"}) {
    const grpc::Status stranger = raw_call(*channel, preview, garbage, token);
    EXPECT_EQ(stranger.error_code(), StatusCode::UNAUTHENTICATED) << "token \"" << token << "\": "
                                                                 << stranger.error_message();
  }
  // The health service stays open to probes without a token.
  EXPECT_TRUE(raw_call(*channel, "/grpc.health.v1.Health/Check", "", "").ok());
}

}  // namespace
}  // namespace hj
