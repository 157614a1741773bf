#include "json_log.h"

#include <atomic>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <mutex>
#include <random>

namespace hj::server {

namespace {

std::atomic<bool> g_enabled{true};

std::string utc_now() {
  const auto now = std::chrono::system_clock::now();
  const std::time_t t = std::chrono::system_clock::to_time_t(now);
  const long ms = long(std::chrono::duration_cast<std::chrono::milliseconds>(now.time_since_epoch()).count() % 1000);
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[40];
  std::snprintf(buf, sizeof buf, "%04d-%02d-%02dT%02d:%02d:%02d.%03ldZ", tm.tm_year + 1900, tm.tm_mon + 1,
                tm.tm_mday, tm.tm_hour, tm.tm_min, tm.tm_sec, ms);
  return buf;
}

}  // namespace

void log_event(const std::string& event, nlohmann::json fields) {
  if (!g_enabled) return;
  nlohmann::json line = {{"time", utc_now()}, {"event", event}};
  line.update(fields);
  static std::mutex mutex;
  const std::string text = line.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
  std::lock_guard lock(mutex);
  std::fputs(text.c_str(), stderr);
}

void set_logging_enabled(bool enabled) { g_enabled = enabled; }

std::string new_request_id() {
  static const std::string tag = [] {
    std::random_device rd;
    char buf[16];
    std::snprintf(buf, sizeof buf, "%06x", unsigned(rd()) & 0xffffffu);
    return std::string(buf);
  }();
  static std::atomic<long> counter{0};
  return tag + "-" + std::to_string(++counter);
}

}  // namespace hj::server
