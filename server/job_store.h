// The device queue on disk: an SQLite database (WAL journal, synchronous=FULL,
// so every state a client was told about survives a crash of the server).
// Schema in server/README.md. Not thread-safe; DeviceQueue serialises calls.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "hapticjam/v1/device_service.pb.h"

struct sqlite3;

namespace hj::server {

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
  // @throws std::runtime_error naming the file on any SQLite error.
  explicit JobStore(const std::filesystem::path& file);
  ~JobStore();
  JobStore(const JobStore&) = delete;
  JobStore& operator=(const JobStore&) = delete;

  std::int64_t add(const std::string& owner, const std::string& name, const hapticjam::v1::Plan& plan);
  std::optional<StoredJob> find(std::int64_t id);
  hapticjam::v1::Plan plan(std::int64_t id);
  // Queued and running jobs in submission order.
  std::vector<StoredJob> active();
  std::vector<StoredJob> recent_finished(int limit);
  int queued_count();

  void set_state(std::int64_t id, hapticjam::v1::JobState state, const std::string& error = "");
  void set_progress(std::int64_t id, int steps_done);
  void add_capture(std::int64_t id, const hapticjam::v1::CaptureFrame& frame);
  std::vector<hapticjam::v1::CaptureFrame> captures(std::int64_t id);

  // Whether the queue is paused, and why; kept across restarts.
  bool paused();
  std::string pause_reason();
  void set_paused(bool paused, const std::string& reason = "");

 private:
  void exec(const std::string& sql);
  std::vector<StoredJob> select_jobs(const std::string& where_order, int limit = -1);

  std::filesystem::path file_;
  sqlite3* db_ = nullptr;
};

bool is_finished(hapticjam::v1::JobState state);

}  // namespace hj::server
