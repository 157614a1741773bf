// The device queue when its SQLite database fails (faults injected into the
// job store, not a real full disk): the device is vented first, the job ends
// `interrupted`, the queue pauses, the device service stops serving until an
// operator resumes; and nothing ends the process.
#include <gtest/gtest.h>
#include <sqlite3.h>

#include <atomic>

#include "device_queue.h"
#include "expect_error.h"
#include "fake_device_link.h"
#include "json_log.h"
#include "scratch_dir.h"
#include "server_fixture.h"
#include "service_error.h"

namespace hj {
namespace {

using namespace testing_support;
using server::DeviceQueue;
using server::JobStore;

const server::Caller kOperator{"alice", server::Role::kOperator};

// A queue on a fake link and a store whose statements fail on request.
struct FaultyQueue {
  explicit FaultyQueue(const std::filesystem::path& dir) : store(dir / "q.db"), queue(store, &link, {}) {
    server::set_logging_enabled(false);
    store.inject_failures([this](const std::string& sql) {
      std::lock_guard lock(mutex);
      if (fail_code == SQLITE_OK || sql.find(fail_on) == std::string::npos) return SQLITE_OK;
      const int code = fail_code;
      if (failures_left > 0 && --failures_left == 0) fail_code = SQLITE_OK;
      return code;
    });
    queue.start([this](bool up) { serving = up; });
  }
  ~FaultyQueue() { queue.stop(); }
  // Fails the statements holding `sql`: `times` of them, or all (0).
  void fail(int code, const std::string& sql, int times = 0) {
    std::lock_guard lock(mutex);
    fail_on = sql;
    failures_left = times;
    fail_code = code;
  }

  FakeDeviceLink link;
  JobStore store;
  DeviceQueue queue;
  std::atomic<bool> serving{false};
  std::mutex mutex;  // guards the three below: the runner's thread reads them
  std::string fail_on;
  int failures_left = 0, fail_code = SQLITE_OK;
};

v1::JobState state_of(DeviceQueue& queue, std::int64_t id) { return queue.get(id).state(); }

TEST(StoreFaults, EachSqliteFailureInTheRunnerVentsInterruptsPausesAndStopsServing) {
  for (const int code : {SQLITE_BUSY, SQLITE_FULL, SQLITE_IOERR, SQLITE_CORRUPT}) {
    SCOPED_TRACE(sqlite3_errstr(code));
    ScratchDir dir(std::to_string(code));
    FaultyQueue f(dir.path);
    ASSERT_TRUE(eventually([&] { return f.serving.load(); }));
    f.link.hold();
    const std::int64_t id = f.queue.submit(kOperator, "job", device_plan({"p 0.3", "j 0 1", "p 0.5"})).id();
    ASSERT_TRUE(eventually([&] { return f.link.waiting() == 1; }));
    const int vents = f.link.vents();
    f.fail(code, "UPDATE jobs SET steps_done", 1);  // the progress write after the first step
    f.link.free_run();
    ASSERT_TRUE(eventually([&] { return !f.serving.load(); }));
    ASSERT_TRUE(eventually([&] { return state_of(f.queue, id) == v1::JOB_STATE_INTERRUPTED; }));
    EXPECT_GT(f.link.vents(), vents);
    const v1::Job job = f.queue.get(id);
    EXPECT_NE(job.error().find(sqlite3_errstr(code)), std::string::npos) << job.error();
    EXPECT_LT(job.steps_done(), 3);
    EXPECT_TRUE(f.queue.queue_state(0).paused());
    expect_error<server::ServiceError>([&] { f.queue.submit(kOperator, "next", device_plan({"p 0.1"})); },
                                       {"job database", sqlite3_errstr(code), "ResumeQueue"});
    // An operator resumes: serving again, and the next job runs.
    f.queue.resume(kOperator);
    EXPECT_TRUE(f.serving.load());
    const std::int64_t next = f.queue.submit(kOperator, "next", device_plan({"p 0.1"})).id();
    ASSERT_TRUE(eventually([&] { return state_of(f.queue, next) == v1::JOB_STATE_DONE; }));
  }
}

TEST(StoreFaults, ADatabaseThatTakesNoWriteIsLoggedAndNothingRunsTwice) {
  ScratchDir dir;
  FaultyQueue f(dir.path);
  ASSERT_TRUE(eventually([&] { return f.serving.load(); }));
  f.link.hold();
  const std::int64_t id = f.queue.submit(kOperator, "job", device_plan({"p 0.3", "p 0.5"})).id();
  ASSERT_TRUE(eventually([&] { return f.link.waiting() == 1; }));
  f.fail(SQLITE_IOERR, "UPDATE");  // every update, the interrupt and the pause included
  f.link.free_run();
  ASSERT_TRUE(eventually([&] { return !f.serving.load(); }));
  ASSERT_TRUE(eventually([&] { return f.link.vents() >= 2; }));  // the job's own, then the failure's
  // The resume fails while the database does, and says why.
  try {
    f.queue.resume(kOperator);
    ADD_FAILURE() << "resume succeeded on a failing database";
  } catch (const server::ServiceError& e) {
    EXPECT_EQ(e.code(), grpc::StatusCode::UNAVAILABLE);
    EXPECT_NE(std::string(e.what()).find("still fails"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(f.serving.load());
  // Fixed: the job that could not be ended is interrupted, not run again.
  f.fail(SQLITE_OK, "");
  const std::size_t steps_sent = f.link.log().size();
  f.queue.resume(kOperator);
  EXPECT_TRUE(f.serving.load());
  EXPECT_EQ(state_of(f.queue, id), v1::JOB_STATE_INTERRUPTED);
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  for (std::size_t i = steps_sent; i < f.link.log().size(); ++i) EXPECT_EQ(f.link.log()[i], "vent");
}

TEST(StoreFaults, AFailureInTheConnectionHandlerDoesNotEndTheProcess) {
  ScratchDir dir;
  FaultyQueue f(dir.path);
  ASSERT_TRUE(eventually([&] { return f.serving.load(); }));
  f.fail(SQLITE_FULL, "INSERT OR REPLACE INTO queue");
  f.link.set_connected(false);  // a drop pauses the queue: that write fails
  f.link.set_connected(true);
  EXPECT_FALSE(f.serving.load());
  expect_error<server::ServiceError>([&] { f.queue.submit(kOperator, "job", device_plan({"p 0.1"})); },
                                     {"database or disk is full"});
  f.fail(SQLITE_OK, "");
  f.queue.resume(kOperator);
  EXPECT_TRUE(f.serving.load());
}

TEST(StoreFaults, ALinkDropBetweenJobsPausesTheQueue) {
  ScratchDir dir;
  FaultyQueue f(dir.path);
  ASSERT_TRUE(eventually([&] { return f.serving.load(); }));
  f.link.set_connected(false);
  f.link.set_connected(true);
  const v1::QueueState state = f.queue.queue_state(0);
  EXPECT_TRUE(state.paused());
  EXPECT_NE(state.pause_reason().find("dropped between jobs"), std::string::npos) << state.pause_reason();
}

TEST(StoreFaults, AStoredPlanThatCannotBeParsedFailsTheJobWithoutRunningIt) {
  ScratchDir dir;
  FaultyQueue f(dir.path);
  ASSERT_TRUE(eventually([&] { return f.serving.load(); }));
  f.queue.resume(kOperator);
  f.link.hold();
  const std::int64_t first = f.queue.submit(kOperator, "first", device_plan({"p 0.3"})).id();
  const std::int64_t broken = f.queue.submit(kOperator, "broken", device_plan({"p 0.4"})).id();
  // The second job's plan is damaged on disk while the first holds the device.
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open((dir.path / "q.db").string().c_str(), &db), SQLITE_OK);
  sqlite3_busy_timeout(db, 5000);
  const std::string sql = "UPDATE jobs SET plan = x'ffffffff0a' WHERE id = " + std::to_string(broken);
  ASSERT_EQ(sqlite3_exec(db, sql.c_str(), nullptr, nullptr, nullptr), SQLITE_OK);
  sqlite3_close(db);
  f.link.free_run();
  ASSERT_TRUE(eventually([&] { return state_of(f.queue, broken) == v1::JOB_STATE_FAILED; }));
  EXPECT_EQ(state_of(f.queue, first), v1::JOB_STATE_DONE);
  const v1::Job job = f.queue.get(broken);
  EXPECT_NE(job.error().find("cannot be parsed"), std::string::npos) << job.error();
  EXPECT_EQ(job.steps_done(), 0);
  for (const std::string& sent : f.link.log()) EXPECT_EQ(sent.find("0.4 kPa"), std::string::npos) << "the broken job ran";
}

TEST(JobStoreSafety, InterruptingAndPausingIsOneTransaction) {
  ScratchDir dir;
  JobStore store(dir.path / "q.db");
  const std::int64_t id = store.add("alice", "job", device_plan({"p 0.3"}));
  store.set_state(id, v1::JOB_STATE_RUNNING);
  store.inject_failures([](const std::string& sql) {
    return sql.find("INTO queue") != std::string::npos ? SQLITE_FULL : SQLITE_OK;
  });
  expect_error<server::StoreError>(
      [&] { store.end_and_pause(id, v1::JOB_STATE_INTERRUPTED, "drop", "paused by a drop"); },
      {"q.db", "database or disk is full"});
  store.inject_failures({});
  // Neither half happened.
  EXPECT_EQ(store.find(id)->state, v1::JOB_STATE_RUNNING);
  EXPECT_FALSE(store.paused());
  store.end_and_pause(id, v1::JOB_STATE_INTERRUPTED, "drop", "paused by a drop");
  EXPECT_EQ(store.find(id)->state, v1::JOB_STATE_INTERRUPTED);
  EXPECT_TRUE(store.paused());
}

TEST(JobStoreSafety, ASecondServerOnTheSameDatabaseIsRefused) {
  ScratchDir dir;
  {
    JobStore first(dir.path / "q.db");
    expect_error<server::StoreError>([&] { JobStore second(dir.path / "q.db"); },
                                     {"q.db", "in use by another server", "q.db.lock"});
  }
  JobStore after(dir.path / "q.db");  // the lock goes with its holder
  EXPECT_FALSE(after.paused());
}

TEST(JobStoreSafety, PruningKeepsTheNewestFinishedJobsAndEveryActiveOne) {
  ScratchDir dir;
  JobStore store(dir.path / "q.db");
  std::vector<std::int64_t> ids;
  for (int i = 0; i < 6; ++i) {
    ids.push_back(store.add("alice", "job " + std::to_string(i), device_plan({"p 0.3", "c"})));
    if (i < 5) {
      v1::CaptureFrame frame;
      frame.set_step_index(1);
      store.add_capture(ids.back(), frame);
      store.set_state(ids.back(), v1::JOB_STATE_DONE);
    }
  }
  EXPECT_EQ(store.prune({2, 0}), 3);
  EXPECT_FALSE(store.find(ids[0]));
  EXPECT_TRUE(store.captures(ids[0]).empty());
  EXPECT_TRUE(store.find(ids[3]) && store.find(ids[4]));
  EXPECT_EQ(store.captures(ids[4]).size(), 1u);
  EXPECT_EQ(store.find(ids[5])->state, v1::JOB_STATE_QUEUED);
  // By age: a job finished 40 days ago goes under a 30-day policy.
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open((dir.path / "q.db").string().c_str(), &db), SQLITE_OK);
  const std::string sql = "UPDATE jobs SET finished_unix_ms = finished_unix_ms - 40 * 86400000 WHERE id = " +
                          std::to_string(ids[3]);
  ASSERT_EQ(sqlite3_exec(db, sql.c_str(), nullptr, nullptr, nullptr), SQLITE_OK);
  sqlite3_close(db);
  EXPECT_EQ(store.prune({1000, 30}), 1);
  EXPECT_FALSE(store.find(ids[3]));
  EXPECT_TRUE(store.find(ids[4]));
}

}  // namespace
}  // namespace hj
