// The device queue on disk: an SQLite database (WAL journal, synchronous=FULL,
// so every state a client was told about survives a crash of the server),
// held by one server at a time (an exclusive lock on FILE.lock). Schema and
// pruning policy in server/README.md. Not thread-safe; DeviceQueue
// serialises calls.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "hapticjam/v1/device_service.pb.h"

struct sqlite3;

namespace hj::server {

// Any failure of the database (cannot open, locked by another server, busy
// past its timeout, full, I/O, corrupt); the message names the file.
class StoreError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A stored plan that cannot be read back: the job fails, the store is fine.
class BadStoredPlan : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// How many finished jobs (with their captures) the store keeps: the newest
// `keep_jobs`, and none finished more than `keep_days` ago. 0 = no bound.
struct PrunePolicy {
  int keep_jobs = 1000;
  int keep_days = 30;
};

struct StoredJob {
  std::int64_t id = 0;
  std::string owner, name;
  hapticjam::v1::JobState state = hapticjam::v1::JOB_STATE_QUEUED;
  int steps_done = 0, steps_total = 0;
  std::string error;
  std::int64_t submitted_unix_ms = 0, finished_unix_ms = 0;
};

class JobStore {
 public:
  // Opens or creates the database. Jobs left `running` by a previous server
  // become `interrupted` ("the server stopped while it ran"), and the queue
  // is paused if there was one.
  // Every method throws StoreError naming the file on any SQLite error.
  // @throws StoreError also when another process holds the database.
  explicit JobStore(const std::filesystem::path& file);
  ~JobStore();
  JobStore(const JobStore&) = delete;
  JobStore& operator=(const JobStore&) = delete;

  std::int64_t add(const std::string& owner, const std::string& name, const hapticjam::v1::Plan& plan);
  std::optional<StoredJob> find(std::int64_t id);
  // @throws BadStoredPlan when the job has no plan that parses.
  hapticjam::v1::Plan plan(std::int64_t id);
  // Queued and running jobs in submission order.
  std::vector<StoredJob> active();
  std::vector<StoredJob> recent_finished(int limit);
  int queued_count();

  void set_state(std::int64_t id, hapticjam::v1::JobState state, const std::string& error = "");
  // Ends every job still `running` as `interrupted` with `why`; returns the
  // first one's id, 0 if none.
  std::int64_t interrupt_running(const std::string& why);
  void set_progress(std::int64_t id, int steps_done);
  void add_capture(std::int64_t id, const hapticjam::v1::CaptureFrame& frame);
  std::vector<hapticjam::v1::CaptureFrame> captures(std::int64_t id);

  // Whether the queue is paused, and why; kept across restarts.
  bool paused();
  std::string pause_reason();
  void set_paused(bool paused, const std::string& reason = "");
  // Ends job `id` as `state` and pauses the queue, in one transaction.
  void end_and_pause(std::int64_t id, hapticjam::v1::JobState state, const std::string& error,
                     const std::string& pause_reason);
  // Deletes the finished jobs (and their captures) that `policy` does not
  // keep; returns how many jobs went.
  int prune(const PrunePolicy& policy);

  // Test only: called with each SQL statement before it runs; a non-zero
  // SQLite result code (SQLITE_FULL, SQLITE_IOERR, ...) fails it as SQLite would.
  using FailureInjector = std::function<int(const std::string& sql)>;
  void inject_failures(FailureInjector injector) { injector_ = std::move(injector); }

 private:
  void exec(const std::string& sql);
  void injected(const std::string& sql) const;
  std::vector<StoredJob> select_jobs(const std::string& where_order, int limit = -1);
  void write_state(std::int64_t id, hapticjam::v1::JobState state, const std::string& error);
  void write_paused(bool paused, const std::string& reason);
  template <class F>
  void transaction(F&& body);

  std::filesystem::path file_;
  int lock_fd_ = -1;  // flock'd FILE.lock, held while the store is open
  sqlite3* db_ = nullptr;
  FailureInjector injector_;
};

bool is_finished(hapticjam::v1::JobState state);

}  // namespace hj::server
