// What a task on the work pool and the gRPC handler waiting for it share:
// the events the task produced (relayed to the caller's stream), its final
// status and result, and the flag that stops it. Shared (std::shared_ptr),
// so a handler whose caller went away can return while its task still waits
// in the queue. Used by PlanningService and CalibrationService.
#pragma once

#include <grpcpp/server_context.h>
#include <grpcpp/support/sync_stream.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <mutex>
#include <optional>
#include <string>

namespace hj::server {

template <class Event, class Result>
struct StreamedWork {
  using Clock = std::chrono::steady_clock;

  std::mutex mutex;
  std::condition_variable changed;
  std::deque<Event> events;
  std::optional<grpc::Status> done;
  Result result{};
  std::atomic<bool> stop{false};
  Clock::time_point deadline = Clock::time_point::max();
  // Why the deadline is what it is: the caller's, or the server's limit (the flag's name).
  std::string deadline_reason = "the caller's deadline";

  // The caller's deadline, if it set one, or `max_time` from now if that is
  // sooner (zero: no server limit; `limit_flag` names the flag that sets it).
  explicit StreamedWork(const grpc::ServerContext& context, std::chrono::milliseconds max_time = {},
                        const std::string& limit_flag = "") {
    const auto now = Clock::now();
    if (context.deadline() != std::chrono::system_clock::time_point::max())
      deadline = now + (context.deadline() - std::chrono::system_clock::now());
    if (max_time > std::chrono::milliseconds::zero() && now + max_time < deadline) {
      deadline = now + max_time;
      const auto ms = max_time.count();
      deadline_reason = "the server's limit of " +
                        (ms % 1000 == 0 ? std::to_string(ms / 1000) + " s" : std::to_string(ms) + " ms") + " (" +
                        limit_flag + ")";
    }
  }

  void push(Event event) {
    std::lock_guard lock(mutex);
    events.push_back(std::move(event));
    changed.notify_all();
  }
  void finish(grpc::Status status, Result r = {}) {
    std::lock_guard lock(mutex);
    done = std::move(status);
    result = std::move(r);
    changed.notify_all();
  }
  // What the task polls (the library's cancellation hooks).
  bool should_stop() const { return stop || Clock::now() > deadline; }
  // The status for a task that stopped because should_stop() said so;
  // `what` names the work ("planning", "the fit").
  grpc::Status stopped_status(const std::string& what) const {
    return Clock::now() > deadline
               ? grpc::Status(grpc::StatusCode::DEADLINE_EXCEEDED, deadline_reason + " passed during " + what)
               : grpc::Status(grpc::StatusCode::CANCELLED, what + " was cancelled");
  }
};

// Relays the work's events to `writer` (null: the task produces none) until
// the task is done, polling every 20 ms for the caller's cancellation and
// the work's deadline (the caller's or the server's limit), either of which sets `stop` and returns CANCELLED /
// DEADLINE_EXCEEDED at once ("... before `what` was done"). Otherwise
// returns the task's status; its result is then in work.result.
template <class Event, class Result>
grpc::Status relay_until_done(grpc::ServerContext* context, grpc::ServerWriter<Event>* writer,
                              StreamedWork<Event, Result>& work, const std::string& what) {
  // The caller's cancellation or the deadline: stops the task, ends the call.
  auto ended = [&]() -> std::optional<grpc::Status> {
    if (StreamedWork<Event, Result>::Clock::now() > work.deadline) {
      work.stop = true;
      return grpc::Status(grpc::StatusCode::DEADLINE_EXCEEDED,
                          work.deadline_reason + " passed before " + what + " was done");
    }
    if (context->IsCancelled()) {
      work.stop = true;
      return grpc::Status(grpc::StatusCode::CANCELLED, "the caller cancelled");
    }
    return std::nullopt;
  };
  std::unique_lock lock(work.mutex);
  for (;;) {
    work.changed.wait_for(lock, std::chrono::milliseconds(20),
                          [&] { return work.done.has_value() || !work.events.empty(); });
    while (writer && !work.events.empty()) {
      Event event = std::move(work.events.front());
      work.events.pop_front();
      lock.unlock();
      const bool written = writer->Write(event);
      lock.lock();
      if (!written) work.stop = true;
      // A task that reports faster than the caller reads must not hold off its deadline.
      if (!work.done)
        if (auto status = ended()) return *status;
    }
    if (work.done) return *work.done;
    if (auto status = ended()) return *status;
  }
}

}  // namespace hj::server
