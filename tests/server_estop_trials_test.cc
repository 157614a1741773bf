// Emergency stops fired at random moments during jobs on the emulated array,
// through the device queue and the real link: once a stop has answered, the
// device receives no action (docs/safety.md). HJ_ESTOP_TRIALS sets the
// number of trials (default 20; scripts/estop_trials.sh runs 1,000).
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <random>

#include "device/make_device_link.h"
#include "device_queue.h"
#include "device_test_support.h"
#include "json_log.h"
#include "scratch_dir.h"
#include "server_fixture.h"

namespace hj {
namespace {

using namespace testing_support;
using Clock = std::chrono::steady_clock;

int trial_count() {
  const char* text = std::getenv("HJ_ESTOP_TRIALS");
  return text ? std::max(1, std::atoi(text)) : 20;
}

long actions_after(const device::EmulatorServer& device, Clock::time_point moment) {
  long count = 0;
  for (const auto& action : device.actions_received()) count += action.at > moment;
  return count;
}

TEST(EmergencyStopTrials, NoActionReachesTheDeviceAfterTheStopAnswers) {
  const int trials = trial_count();
  ScratchDir dir;
  server::set_logging_enabled(false);
  EmulatedDevice device;
  server::JobStore store(dir.path / "q.db");
  const auto link = device::make_device_link(device.endpoint());
  server::DeviceQueue queue(store, link.get(), {});
  queue.start();
  ASSERT_TRUE(eventually([&] { return queue.device_status().connected(); }, 20.0));

  const server::Caller caller{"trials", server::Role::kOperator};
  const v1::Plan plan = device_plan({"p 0.4", "j 0 1", "p 0.8", "n 1 1", "p 0.3", "u 0 1", "p 0.6", "c"});
  std::mt19937_64 random(23);
  std::uniform_int_distribution<int> delay_us(0, 40'000);
  long sent_after_answer = 0;
  int mid_job = 0;
  for (int t = 0; t < trials; ++t) {
    const std::int64_t id = queue.submit(caller, "trial " + std::to_string(t), plan).id();
    ASSERT_TRUE(eventually([&] { return queue.get(id).state() != v1::JOB_STATE_QUEUED; }, 20.0));
    std::this_thread::sleep_for(std::chrono::microseconds(delay_us(random)));
    const v1::DeviceStatus stopped = queue.emergency_stop(caller, "trial " + std::to_string(t));
    const Clock::time_point answered = Clock::now();
    EXPECT_TRUE(stopped.emergency_stopped());
    EXPECT_EQ(stopped.pressure_pa(), 0.0);
    ASSERT_TRUE(eventually([&] { return server::is_finished(queue.get(id).state()); }, 20.0));
    const v1::Job job = queue.get(id);
    if (job.state() == v1::JOB_STATE_INTERRUPTED) ++mid_job;
    else EXPECT_EQ(job.state(), v1::JOB_STATE_DONE) << job.error();
    // Time for a line sent late to arrive, had there been one.
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
    sent_after_answer += actions_after(device.server, answered);
    queue.resume(caller);
  }
  std::printf("[estop trials] %d trials, %d stopped mid-job, %ld actions received after a stop had answered\n",
              trials, mid_job, sent_after_answer);
  EXPECT_EQ(sent_after_answer, 0);
  EXPECT_GT(mid_job, 0);
  queue.stop();
}

}  // namespace
}  // namespace hj
