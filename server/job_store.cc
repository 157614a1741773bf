#include "job_store.h"

#include <sqlite3.h>

#include <chrono>
#include <stdexcept>

namespace hj::server {

namespace v1 = ::hapticjam::v1;

namespace {

std::int64_t now_unix_ms() {
  return std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

// One prepared statement, finalised on scope exit.
class Statement {
 public:
  Statement(sqlite3* db, const std::string& sql, const std::filesystem::path& file) : db_(db), file_(file) {
    if (sqlite3_prepare_v2(db, sql.c_str(), -1, &stmt_, nullptr) != SQLITE_OK) fail("prepare");
  }
  ~Statement() { sqlite3_finalize(stmt_); }
  Statement& bind(int i, std::int64_t v) { return check(sqlite3_bind_int64(stmt_, i, v)); }
  Statement& bind(int i, const std::string& v) {
    return check(sqlite3_bind_text(stmt_, i, v.data(), int(v.size()), SQLITE_TRANSIENT));
  }
  Statement& bind_blob(int i, const std::string& v) {
    return check(sqlite3_bind_blob(stmt_, i, v.data(), int(v.size()), SQLITE_TRANSIENT));
  }
  // True while there is a row.
  bool step() {
    const int rc = sqlite3_step(stmt_);
    if (rc == SQLITE_ROW) return true;
    if (rc != SQLITE_DONE) fail("step");
    return false;
  }
  std::int64_t integer(int col) const { return sqlite3_column_int64(stmt_, col); }
  std::string text(int col) const {
    const void* data = sqlite3_column_blob(stmt_, col);
    return data ? std::string(static_cast<const char*>(data), size_t(sqlite3_column_bytes(stmt_, col))) : "";
  }

 private:
  Statement& check(int rc) {
    if (rc != SQLITE_OK) fail("bind");
    return *this;
  }
  [[noreturn]] void fail(const char* what) const {
    throw std::runtime_error("job database \"" + file_.string() + "\": " + what + ": " + sqlite3_errmsg(db_));
  }
  sqlite3* db_;
  sqlite3_stmt* stmt_ = nullptr;
  const std::filesystem::path& file_;
};

const char* kSchema = R"sql(
CREATE TABLE IF NOT EXISTS jobs (
  id INTEGER PRIMARY KEY AUTOINCREMENT,
  owner TEXT NOT NULL,
  name TEXT NOT NULL,
  plan BLOB NOT NULL,
  state INTEGER NOT NULL,
  steps_done INTEGER NOT NULL DEFAULT 0,
  steps_total INTEGER NOT NULL,
  error TEXT NOT NULL DEFAULT '',
  submitted_unix_ms INTEGER NOT NULL,
  finished_unix_ms INTEGER NOT NULL DEFAULT 0
);
CREATE INDEX IF NOT EXISTS jobs_by_state ON jobs (state, id);
CREATE TABLE IF NOT EXISTS captures (
  job_id INTEGER NOT NULL REFERENCES jobs (id),
  step_index INTEGER NOT NULL,
  frame BLOB NOT NULL,
  PRIMARY KEY (job_id, step_index)
);
CREATE TABLE IF NOT EXISTS queue (
  key TEXT PRIMARY KEY,
  value TEXT NOT NULL
);
)sql";

}  // namespace

bool is_finished(v1::JobState state) {
  return state != v1::JOB_STATE_QUEUED && state != v1::JOB_STATE_RUNNING;
}

JobStore::JobStore(const std::filesystem::path& file) : file_(file) {
  if (sqlite3_open(file.string().c_str(), &db_) != SQLITE_OK) {
    const std::string why = db_ ? sqlite3_errmsg(db_) : "out of memory";
    sqlite3_close(db_);
    throw std::runtime_error("cannot open job database \"" + file.string() + "\": " + why);
  }
  sqlite3_busy_timeout(db_, 5000);
  try {
    exec("PRAGMA journal_mode=WAL");
    exec("PRAGMA synchronous=FULL");
    exec(kSchema);
    const auto running = select_jobs("state = " + std::to_string(v1::JOB_STATE_RUNNING) + " ORDER BY id");
    for (const StoredJob& job : running)
      set_state(job.id, v1::JOB_STATE_INTERRUPTED, "the server stopped while the job ran");
    if (!running.empty())
      set_paused(true, "job " + std::to_string(running.front().id) +
                           " was interrupted by a server restart; an operator must resume the queue");
  } catch (...) {
    sqlite3_close(db_);
    throw;
  }
}

JobStore::~JobStore() { sqlite3_close(db_); }

void JobStore::exec(const std::string& sql) {
  char* error = nullptr;
  if (sqlite3_exec(db_, sql.c_str(), nullptr, nullptr, &error) != SQLITE_OK) {
    const std::string why = error ? error : "unknown error";
    sqlite3_free(error);
    throw std::runtime_error("job database \"" + file_.string() + "\": " + why);
  }
}

std::int64_t JobStore::add(const std::string& owner, const std::string& name, const v1::Plan& plan) {
  Statement s(db_,
              "INSERT INTO jobs (owner, name, plan, state, steps_total, submitted_unix_ms) VALUES (?, ?, ?, ?, ?, ?)",
              file_);
  s.bind(1, owner).bind(2, name).bind_blob(3, plan.SerializeAsString());
  s.bind(4, std::int64_t(v1::JOB_STATE_QUEUED)).bind(5, std::int64_t(plan.steps_size())).bind(6, now_unix_ms());
  s.step();
  return sqlite3_last_insert_rowid(db_);
}

std::vector<StoredJob> JobStore::select_jobs(const std::string& where_order, int limit) {
  Statement s(db_,
              "SELECT id, owner, name, state, steps_done, steps_total, error, submitted_unix_ms, finished_unix_ms "
              "FROM jobs WHERE " + where_order + " LIMIT " + std::to_string(limit),
              file_);
  std::vector<StoredJob> out;
  while (s.step()) {
    StoredJob& j = out.emplace_back();
    j.id = s.integer(0);
    j.owner = s.text(1);
    j.name = s.text(2);
    j.state = v1::JobState(s.integer(3));
    j.steps_done = int(s.integer(4));
    j.steps_total = int(s.integer(5));
    j.error = s.text(6);
    j.submitted_unix_ms = s.integer(7);
    j.finished_unix_ms = s.integer(8);
  }
  return out;
}

std::optional<StoredJob> JobStore::find(std::int64_t id) {
  auto jobs = select_jobs("id = " + std::to_string(id));
  if (jobs.empty()) return std::nullopt;
  return jobs.front();
}

v1::Plan JobStore::plan(std::int64_t id) {
  Statement s(db_, "SELECT plan FROM jobs WHERE id = ?", file_);
  s.bind(1, id);
  v1::Plan plan;
  if (s.step()) plan.ParseFromString(s.text(0));
  return plan;
}

std::vector<StoredJob> JobStore::active() {
  return select_jobs("state IN (" + std::to_string(v1::JOB_STATE_RUNNING) + ", " +
                     std::to_string(v1::JOB_STATE_QUEUED) + ") ORDER BY state = " +
                     std::to_string(v1::JOB_STATE_QUEUED) + ", id");
}

std::vector<StoredJob> JobStore::recent_finished(int limit) {
  return select_jobs("state NOT IN (" + std::to_string(v1::JOB_STATE_RUNNING) + ", " +
                         std::to_string(v1::JOB_STATE_QUEUED) + ") ORDER BY id DESC",
                     limit);
}

int JobStore::queued_count() {
  Statement s(db_, "SELECT COUNT(*) FROM jobs WHERE state = ?", file_);
  s.bind(1, std::int64_t(v1::JOB_STATE_QUEUED));
  s.step();
  return int(s.integer(0));
}

void JobStore::set_state(std::int64_t id, v1::JobState state, const std::string& error) {
  Statement s(db_, "UPDATE jobs SET state = ?, error = ?, finished_unix_ms = ? WHERE id = ?", file_);
  s.bind(1, std::int64_t(state)).bind(2, error).bind(3, is_finished(state) ? now_unix_ms() : 0).bind(4, id);
  s.step();
}

void JobStore::set_progress(std::int64_t id, int steps_done) {
  Statement s(db_, "UPDATE jobs SET steps_done = ? WHERE id = ?", file_);
  s.bind(1, std::int64_t(steps_done)).bind(2, id);
  s.step();
}

void JobStore::add_capture(std::int64_t id, const v1::CaptureFrame& frame) {
  Statement s(db_, "INSERT OR REPLACE INTO captures (job_id, step_index, frame) VALUES (?, ?, ?)", file_);
  s.bind(1, id).bind(2, std::int64_t(frame.step_index())).bind_blob(3, frame.SerializeAsString());
  s.step();
}

std::vector<v1::CaptureFrame> JobStore::captures(std::int64_t id) {
  Statement s(db_, "SELECT frame FROM captures WHERE job_id = ? ORDER BY step_index", file_);
  s.bind(1, id);
  std::vector<v1::CaptureFrame> out;
  while (s.step()) out.emplace_back().ParseFromString(s.text(0));
  return out;
}

bool JobStore::paused() {
  Statement s(db_, "SELECT value FROM queue WHERE key = 'paused'", file_);
  return s.step() && s.text(0) == "1";
}

std::string JobStore::pause_reason() {
  Statement s(db_, "SELECT value FROM queue WHERE key = 'pause_reason'", file_);
  return s.step() ? s.text(0) : "";
}

void JobStore::set_paused(bool paused, const std::string& reason) {
  exec("BEGIN");
  try {
    Statement a(db_, "INSERT OR REPLACE INTO queue (key, value) VALUES ('paused', ?)", file_);
    a.bind(1, std::string(paused ? "1" : "0")).step();
    Statement b(db_, "INSERT OR REPLACE INTO queue (key, value) VALUES ('pause_reason', ?)", file_);
    b.bind(1, paused ? reason : std::string()).step();
    exec("COMMIT");
  } catch (...) {
    exec("ROLLBACK");
    throw;
  }
}

}  // namespace hj::server
