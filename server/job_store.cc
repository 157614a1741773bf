#include "job_store.h"

#include <fcntl.h>
#include <sqlite3.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <stdexcept>

namespace hj::server {

namespace v1 = ::hapticjam::v1;

namespace {

std::int64_t now_unix_ms() {
  return std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

std::string store_message(const std::filesystem::path& file, const std::string& what) {
  return "job database \"" + file.string() + "\": " + what;
}

// One prepared statement, finalised on scope exit.
class Statement {
 public:
  Statement(sqlite3* db, const std::string& sql, const std::filesystem::path& file,
            const JobStore::FailureInjector& injector = {})
      : db_(db), file_(file) {
    if (injector)
      if (const int code = injector(sql); code != SQLITE_OK)
        throw StoreError(store_message(file_, std::string("step: ") + sqlite3_errstr(code) + " (injected)"));
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
    throw StoreError(store_message(file_, std::string(what) + ": " + sqlite3_errmsg(db_)));
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

// One server per database: an exclusive flock on FILE.lock, released by
// the kernel however the holder ends (no stale lock after a kill -9).
int lock_exclusively(const std::filesystem::path& file) {
  const std::string lock_file = file.string() + ".lock";
  const int fd = ::open(lock_file.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0600);
  if (fd < 0)
    throw StoreError("cannot open job database \"" + file.string() + "\": cannot create its lock \"" + lock_file +
                     "\": " + std::strerror(errno));
  if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
    const int error = errno;
    ::close(fd);
    throw StoreError("job database \"" + file.string() + "\" is in use by another server (its lock \"" + lock_file +
                     "\" is held" + (error == EWOULDBLOCK ? "" : std::string(": ") + std::strerror(error)) +
                     "); two servers must not share one device queue");
  }
  return fd;
}

}  // namespace

bool is_finished(v1::JobState state) {
  return state != v1::JOB_STATE_QUEUED && state != v1::JOB_STATE_RUNNING;
}

JobStore::JobStore(const std::filesystem::path& file) : file_(file), lock_fd_(lock_exclusively(file)) {
  if (sqlite3_open(file.string().c_str(), &db_) != SQLITE_OK) {
    const std::string why = db_ ? sqlite3_errmsg(db_) : "out of memory";
    sqlite3_close(db_);
    ::close(lock_fd_);
    throw StoreError("cannot open job database \"" + file.string() + "\": " + why);
  }
  sqlite3_busy_timeout(db_, 5000);
  try {
    exec("PRAGMA journal_mode=WAL");
    exec("PRAGMA synchronous=FULL");
    exec(kSchema);
    const std::int64_t first = interrupt_running("the server stopped while the job ran");
    if (first != 0)
      set_paused(true, "job " + std::to_string(first) +
                           " was interrupted by a server restart; an operator must resume the queue");
  } catch (...) {
    sqlite3_close(db_);
    ::close(lock_fd_);
    throw;
  }
}

JobStore::~JobStore() {
  sqlite3_close(db_);
  ::close(lock_fd_);
}

void JobStore::injected(const std::string& sql) const {
  if (!injector_) return;
  if (const int code = injector_(sql); code != SQLITE_OK)
    throw StoreError(store_message(file_, std::string(sqlite3_errstr(code)) + " (injected)"));
}

void JobStore::exec(const std::string& sql) {
  injected(sql);
  char* error = nullptr;
  if (sqlite3_exec(db_, sql.c_str(), nullptr, nullptr, &error) != SQLITE_OK) {
    const std::string why = error ? error : sqlite3_errmsg(db_);
    sqlite3_free(error);
    throw StoreError(store_message(file_, why));
  }
}

template <class F>
void JobStore::transaction(F&& body) {
  exec("BEGIN IMMEDIATE");
  try {
    body();
    exec("COMMIT");
  } catch (...) {
    sqlite3_exec(db_, "ROLLBACK", nullptr, nullptr, nullptr);  // a failed COMMIT may have rolled back already
    throw;
  }
}

std::int64_t JobStore::add(const std::string& owner, const std::string& name, const v1::Plan& plan) {
  Statement s(db_,
              "INSERT INTO jobs (owner, name, plan, state, steps_total, submitted_unix_ms) VALUES (?, ?, ?, ?, ?, ?)",
              file_, injector_);
  s.bind(1, owner).bind(2, name).bind_blob(3, plan.SerializeAsString());
  s.bind(4, std::int64_t(v1::JOB_STATE_QUEUED)).bind(5, std::int64_t(plan.steps_size())).bind(6, now_unix_ms());
  s.step();
  return sqlite3_last_insert_rowid(db_);
}

std::vector<StoredJob> JobStore::select_jobs(const std::string& where_order, int limit) {
  Statement s(db_,
              "SELECT id, owner, name, state, steps_done, steps_total, error, submitted_unix_ms, finished_unix_ms "
              "FROM jobs WHERE " + where_order + " LIMIT " + std::to_string(limit),
              file_, injector_);
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
  Statement s(db_, "SELECT plan FROM jobs WHERE id = ?", file_, injector_);
  s.bind(1, id);
  if (!s.step()) throw BadStoredPlan("job " + std::to_string(id) + " has no stored plan");
  const std::string bytes = s.text(0);
  v1::Plan plan;
  if (!plan.ParseFromString(bytes))
    throw BadStoredPlan("the stored plan of job " + std::to_string(id) + " (" + std::to_string(bytes.size()) +
                        " bytes) cannot be parsed");
  if (plan.steps_size() == 0) throw BadStoredPlan("the stored plan of job " + std::to_string(id) + " has no steps");
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
  Statement s(db_, "SELECT COUNT(*) FROM jobs WHERE state = ?", file_, injector_);
  s.bind(1, std::int64_t(v1::JOB_STATE_QUEUED));
  s.step();
  return int(s.integer(0));
}

void JobStore::set_state(std::int64_t id, v1::JobState state, const std::string& error) {
  write_state(id, state, error);
}

void JobStore::write_state(std::int64_t id, v1::JobState state, const std::string& error) {
  Statement s(db_, "UPDATE jobs SET state = ?, error = ?, finished_unix_ms = ? WHERE id = ?", file_, injector_);
  s.bind(1, std::int64_t(state)).bind(2, error).bind(3, is_finished(state) ? now_unix_ms() : 0).bind(4, id);
  s.step();
}

std::int64_t JobStore::interrupt_running(const std::string& why) {
  const auto running = select_jobs("state = " + std::to_string(v1::JOB_STATE_RUNNING) + " ORDER BY id");
  transaction([&] {
    for (const StoredJob& job : running) write_state(job.id, v1::JOB_STATE_INTERRUPTED, why);
  });
  return running.empty() ? 0 : running.front().id;
}

void JobStore::set_progress(std::int64_t id, int steps_done) {
  Statement s(db_, "UPDATE jobs SET steps_done = ? WHERE id = ?", file_, injector_);
  s.bind(1, std::int64_t(steps_done)).bind(2, id);
  s.step();
}

void JobStore::add_capture(std::int64_t id, const v1::CaptureFrame& frame) {
  Statement s(db_, "INSERT OR REPLACE INTO captures (job_id, step_index, frame) VALUES (?, ?, ?)", file_, injector_);
  s.bind(1, id).bind(2, std::int64_t(frame.step_index())).bind_blob(3, frame.SerializeAsString());
  s.step();
}

std::vector<v1::CaptureFrame> JobStore::captures(std::int64_t id) {
  Statement s(db_, "SELECT frame FROM captures WHERE job_id = ? ORDER BY step_index", file_, injector_);
  s.bind(1, id);
  std::vector<v1::CaptureFrame> out;
  while (s.step()) out.emplace_back().ParseFromString(s.text(0));
  return out;
}

bool JobStore::paused() {
  Statement s(db_, "SELECT value FROM queue WHERE key = 'paused'", file_, injector_);
  return s.step() && s.text(0) == "1";
}

std::string JobStore::pause_reason() {
  Statement s(db_, "SELECT value FROM queue WHERE key = 'pause_reason'", file_, injector_);
  return s.step() ? s.text(0) : "";
}

void JobStore::set_paused(bool paused, const std::string& reason) {
  transaction([&] { write_paused(paused, reason); });
}

void JobStore::write_paused(bool paused, const std::string& reason) {
  Statement a(db_, "INSERT OR REPLACE INTO queue (key, value) VALUES ('paused', ?)", file_, injector_);
  a.bind(1, std::string(paused ? "1" : "0")).step();
  Statement b(db_, "INSERT OR REPLACE INTO queue (key, value) VALUES ('pause_reason', ?)", file_, injector_);
  b.bind(1, paused ? reason : std::string()).step();
}

void JobStore::end_and_pause(std::int64_t id, v1::JobState state, const std::string& error,
                             const std::string& pause_reason) {
  transaction([&] {
    write_state(id, state, error);
    write_paused(true, pause_reason);
  });
}

int JobStore::prune(const PrunePolicy& policy) {
  std::string finished = "state NOT IN (" + std::to_string(v1::JOB_STATE_RUNNING) + ", " +
                         std::to_string(v1::JOB_STATE_QUEUED) + ")";
  std::vector<std::string> beyond;
  if (policy.keep_jobs > 0)
    beyond.push_back("id NOT IN (SELECT id FROM jobs WHERE " + finished + " ORDER BY id DESC LIMIT " +
                     std::to_string(policy.keep_jobs) + ")");
  if (policy.keep_days > 0)
    beyond.push_back("finished_unix_ms < " +
                     std::to_string(now_unix_ms() - std::int64_t(policy.keep_days) * 24 * 3600 * 1000));
  if (beyond.empty()) return 0;
  std::string where = finished + " AND (" + beyond[0] + (beyond.size() > 1 ? " OR " + beyond[1] : "") + ")";
  int removed = 0;
  transaction([&] {
    exec("DELETE FROM captures WHERE job_id IN (SELECT id FROM jobs WHERE " + where + ")");
    exec("DELETE FROM jobs WHERE " + where);
    removed = sqlite3_changes(db_);
  });
  return removed;
}

}  // namespace hj::server
