// The server with the real device link (Asio, src/device) to an in-process
// device emulator: a job runs and its capture comes back; a dropped
// connection mid-job interrupts it, the device is vented on reconnect and the
// queue waits for an operator; a clean shutdown vents.
#include <gtest/gtest.h>

#include "device/make_device_link.h"
#include "device_test_support.h"
#include "server_fixture.h"

namespace hj {
namespace {

using namespace testing_support;

struct EmulatorServerFixture {
  explicit EmulatorServerFixture(const std::filesystem::path& dir) {
    server::set_logging_enabled(false);
    server::ServerOptions o;
    o.listen = "127.0.0.1:0";
    o.db_file = (dir / "q.db").string();
    o.workers = 1;
    server = std::make_unique<server::HapticServer>(o, device::make_device_link(emulated.endpoint()));
    auto channel = grpc::CreateChannel("127.0.0.1:" + std::to_string(server->port()), grpc::InsecureChannelCredentials());
    stub = v1::DeviceService::NewStub(channel);
  }
  v1::Job job(std::int64_t id) {
    v1::GetJobRequest request;
    request.set_id(id);
    v1::Job out;
    stub->GetJob(call().get(), request, &out);
    return out;
  }
  v1::DeviceStatus status() {
    v1::DeviceStatus out;
    stub->GetDeviceStatus(call().get(), {}, &out);
    return out;
  }
  v1::Job submit(const v1::Plan& plan) {
    v1::SubmitJobRequest request;
    *request.mutable_plan() = plan;
    v1::SubmitJobResponse response;
    const grpc::Status status = stub->SubmitJob(call().get(), request, &response);
    EXPECT_TRUE(status.ok()) << status.error_message();
    return response.job();
  }

  EmulatedDevice emulated;
  std::unique_ptr<server::HapticServer> server;
  std::unique_ptr<v1::DeviceService::Stub> stub;
};

TEST(ServerWithEmulator, RunsAJobAndReturnsItsCapture) {
  ScratchDir dir;
  EmulatorServerFixture f(dir.path);
  ASSERT_TRUE(testing_support::eventually([&] { return f.status().connected(); }, 20.0));
  const v1::Job submitted = f.submit(device_plan({"p 0.301", "j 0 1", "c"}));
  ASSERT_TRUE(testing_support::eventually([&] { return f.job(submitted.id()).state() == v1::JOB_STATE_DONE; }, 60.0));
  const v1::Job done = f.job(submitted.id());
  ASSERT_EQ(done.captures_size(), 1);
  EXPECT_EQ(done.captures(0).grid().nx(), 77);  // 2 mm over 3 x 4 cells of 38 mm
  EXPECT_EQ(done.captures(0).grid().ny(), 58);
  EXPECT_EQ(done.captures(0).heights_mm_size(), 77 * 58);
  EXPECT_NEAR(f.status().pressure_pa(), 301.0, 1e-9);
}

TEST(ServerWithEmulator, ADroppedConnectionInterruptsTheJobAndTheDeviceIsVentedBeforeAnythingRuns) {
  ScratchDir dir;
  EmulatorServerFixture f(dir.path);
  ASSERT_TRUE(testing_support::eventually([&] { return f.status().connected(); }, 20.0));
  f.emulated.server.stall(std::chrono::milliseconds(1500));  // the job's first command hangs
  const v1::Job first = f.submit(device_plan({"p 0.5", "p 1.0"}));
  const v1::Job second = f.submit(device_plan({"p 0.2"}));
  ASSERT_TRUE(testing_support::eventually([&] { return f.job(first.id()).state() == v1::JOB_STATE_RUNNING; }, 20.0));
  f.emulated.server.drop_connections();
  ASSERT_TRUE(testing_support::eventually([&] { return f.job(first.id()).state() == v1::JOB_STATE_INTERRUPTED; }, 20.0));
  // Reconnected and vented (pressure 0), but the next job waits for an admin.
  ASSERT_TRUE(testing_support::eventually(
      [&] {
        const v1::DeviceStatus s = f.status();
        return s.connected() && s.queue_paused() && s.pressure_pa() == 0.0 && s.last_error().find("vent failed") == std::string::npos;
      },
      30.0));
  EXPECT_EQ(f.job(second.id()).state(), v1::JOB_STATE_QUEUED);
  v1::QueueState resumed;
  ASSERT_TRUE(f.stub->ResumeQueue(call().get(), {}, &resumed).ok());
  ASSERT_TRUE(testing_support::eventually([&] { return f.job(second.id()).state() == v1::JOB_STATE_DONE; }, 60.0));
}

// SIGINT and SIGTERM end in shutdown(): the array is vented before the link closes.
TEST(ServerWithEmulator, ACleanShutdownVentsTheDeviceFirst) {
  ScratchDir dir;
  EmulatorServerFixture f(dir.path);
  ASSERT_TRUE(testing_support::eventually([&] { return f.status().connected(); }, 20.0));
  const v1::Job job = f.submit(device_plan({"p 0.6", "j 0 1"}));
  ASSERT_TRUE(testing_support::eventually([&] { return f.job(job.id()).state() == v1::JOB_STATE_DONE; }, 60.0));
  const std::size_t vents = f.emulated.server.vents().size();
  f.server->shutdown();
  const auto after = f.emulated.server.vents();
  ASSERT_GT(after.size(), vents);
  EXPECT_EQ(after[vents].why, "vent");  // the server's own, not the device's reaction to the closed link
}

}  // namespace
}  // namespace hj
