// Structured logs: one JSON object per line on stderr, each with a time, an
// event name and, for requests, the request id (docs: server/README.md).
#pragma once

#include <nlohmann/json.hpp>
#include <string>

namespace hj::server {

// Writes {"time": ISO-8601 UTC, "event": event, ...fields} as one line.
// Thread-safe; lines never interleave.
void log_event(const std::string& event, nlohmann::json fields = nlohmann::json::object());

// Silences log_event (tests that would flood the output).
void set_logging_enabled(bool enabled);

// A new id for a request: "r" + a process-unique counter, prefixed by a
// per-process random tag so ids from restarts differ.
std::string new_request_id();

}  // namespace hj::server
