// The io thread's side of AsioDeviceLink: the connection, reconnection with
// backoff, the heartbeat, the commands in flight and the halt. Private to
// asio_device_link.cc, which holds the caller-facing methods.
#pragma once

#include "device/asio_device_link.h"

#include <algorithm>
#include <array>
#include <atomic>
// Boost 1.74's asio/awaitable.hpp uses std::exchange without <utility>.
#include <utility>
// clang-format off
#include <boost/asio.hpp>
// clang-format on
#include <deque>
#include <future>
#include <map>
#include <mutex>
#include <optional>
#include <thread>

#include "device/line_buffer.h"
#include "device/protocol.h"
#include "device/serial_line.h"
#include "device/status_mirror.h"

namespace hj::device {

namespace asio = boost::asio;
using asio::ip::tcp;
using Clock = std::chrono::steady_clock;
using Kind = DeviceError::Kind;

namespace link_detail {

// How a command ended, as the io thread hands it to the waiting caller
// (who builds any exception in its own thread).
struct Outcome {
  protocol::Reply reply;
  std::string dropped;  // non-empty: the link dropped, and why
};

// A command a caller waits for; the io thread fulfils it.
struct Pending {
  std::string what;  // the command as sent, for messages
  std::promise<Outcome> outcome;
};

inline long long ms(std::chrono::milliseconds d) { return static_cast<long long>(d.count()); }

}  // namespace link_detail

using link_detail::ms;
using link_detail::Outcome;
using link_detail::Pending;

struct AsioDeviceLink::Impl {
  Impl(Endpoint e, LinkOptions o)
      : endpoint(std::move(e)),
        options(o),
        resolver(io),
        connect_timer(io),
        heartbeat_timer(io),
        reconnect_timer(io),
        lines(protocol::kMaxReplyBytes),
        backoff(o.backoff_initial) {
    status.endpoint = endpoint.to_string();
  }

  const Endpoint endpoint;
  const LinkOptions options;
  asio::io_context io;
  std::optional<asio::executor_work_guard<asio::io_context::executor_type>> work;
  std::thread thread;
  // Connection callbacks run here, not on the io thread, so that a callback
  // may itself send commands (vent on reconnect) without blocking the link.
  asio::io_context notify_io;
  std::optional<asio::executor_work_guard<asio::io_context::executor_type>> notify_work;
  std::thread notify_thread;

  // Used on the io thread only.
  tcp::resolver resolver;
  std::optional<tcp::socket> socket;
  std::optional<asio::serial_port> serial;
  asio::steady_timer connect_timer, heartbeat_timer, reconnect_timer;
  LineBuffer lines;
  std::array<char, 64 * 1024> read_buffer{};
  std::deque<std::string> write_queue;
  std::map<std::uint64_t, std::function<void(const protocol::Reply&)>> internal;  // hello, status, ping
  Clock::time_point last_data;  // bytes of a long reply count as life too
  bool ping_outstanding = false;
  std::chrono::milliseconds backoff;

  // Shared with callers, under `mutex`.
  mutable std::mutex mutex;
  std::map<std::uint64_t, std::shared_ptr<Pending>> pending;
  bool up = false;
  bool stopping = false;
  bool halted = false;  // actions are refused unsent (halt_and_vent)
  // Vents mirrored so far: an action acknowledged before a vent but mirrored
  // after it (its caller's thread ran late) must not undo the vent's mirror.
  std::uint64_t vents_mirrored = 0;
  DeviceStatus status;
  std::function<void(bool)> callback;
  // Bumped (under `mutex`) on every connection attempt and every drop, so
  // that handlers and queued writes of an old connection do nothing on a
  // new one.
  std::atomic<unsigned> generation{0};
  std::atomic<std::uint64_t> next_id{1};

  // --- io thread -----------------------------------------------------------

  template <class F>
  void with_stream(F&& f) {
    if (socket) f(*socket);
    else if (serial) f(*serial);
  }

  void connect() {
    unsigned gen = 0;
    {
      std::lock_guard lock(mutex);
      gen = ++generation;
    }
    connect_timer.expires_after(options.connect_timeout);
    connect_timer.async_wait([this, gen](boost::system::error_code ec) {
      if (!ec && gen == generation) fail(gen, "no hello within " + std::to_string(ms(options.connect_timeout)) + " ms");
    });
    if (endpoint.kind == Endpoint::Kind::kSerial) {
      serial.emplace(io);
      const boost::system::error_code ec = open_serial_line(*serial, endpoint.device, options.baud_rate);
      if (ec) {
        asio::post(io, [this, gen, m = ec.message()] { fail(gen, "cannot open: " + m); });
        return;
      }
      opened(gen);
      return;
    }
    socket.emplace(io);
    resolver.async_resolve(endpoint.host, std::to_string(endpoint.port),
                           [this, gen](boost::system::error_code ec, tcp::resolver::results_type results) {
                             if (gen != generation) return;
                             if (ec) return fail(gen, "cannot resolve: " + ec.message());
                             connect_to(gen, results);
                           });
  }

  void connect_to(unsigned gen, const tcp::resolver::results_type& addresses) {
    asio::async_connect(*socket, addresses, [this, gen](boost::system::error_code ec, const tcp::endpoint&) {
      if (gen != generation) return;
      if (ec) return fail(gen, "cannot connect: " + ec.message());
      socket->set_option(tcp::no_delay(true), ec);
      opened(gen);
    });
  }

  // The stream is open: say hello, read the state, then report "up".
  void opened(unsigned gen) {
    last_data = Clock::now();
    read(gen);
    send_internal(gen, "hello", [this, gen](const protocol::Reply& r) {
      if (!r.ok) return fail(gen, "hello refused: " + r.code + " " + r.text);
      const protocol::Hello hello = protocol::parse_hello(r.text);
      if (hello.protocol != protocol::kVersion)
        return fail(gen, "device speaks protocol " + std::to_string(hello.protocol) + ", this link " +
                             std::to_string(protocol::kVersion));
      {
        std::lock_guard lock(mutex);
        status.rows = hello.rows;
        status.cols = hello.cols;
        status.cell_mm = hello.cell_mm;
        status.max_pressure_pa = hello.max_pressure_pa;
      }
      send_internal(gen, "status", [this, gen, hello](const protocol::Reply& r) {
        if (!r.ok) return fail(gen, "status refused: " + r.code + " " + r.text);
        const protocol::StatusPayload s = protocol::parse_status(r.text, hello.rows, hello.cols);
        connect_timer.cancel();
        backoff = options.backoff_initial;
        {
          std::lock_guard lock(mutex);
          up = true;
          status.connected = true;
          status.pressure_pa = s.pressure_pa;
          status.cell_jammed = s.cell_jammed;
          status.node_pinned = s.node_pinned;
        }
        beat(gen);
        notify(true);
      });
    });
  }

  void read(unsigned gen) {
    with_stream([&](auto& stream) {
      stream.async_read_some(asio::buffer(read_buffer), [this, gen](boost::system::error_code ec, std::size_t n) {
        if (gen != generation) return;
        if (ec) return fail(gen, ec == asio::error::eof ? "the device closed the connection" : ec.message());
        last_data = Clock::now();
        try {
          lines.feed(
              std::string_view(read_buffer.data(), n), [&](std::string_view line) { received(gen, line); },
              [&] {
                throw protocol::ProtocolError(protocol::ErrorCode::kTooLong, 0, "a reply line exceeds the limit");
              });
        } catch (const std::exception& e) {
          return fail(gen, std::string("bad reply: ") + e.what());
        }
        if (gen == generation) read(gen);
      });
    });
  }

  void received(unsigned gen, std::string_view line) {
    if (gen != generation || line.empty()) return;
    const protocol::Reply reply = protocol::parse_reply(line);
    if (const auto it = internal.find(reply.id); it != internal.end()) {
      const auto handler = std::move(it->second);
      internal.erase(it);
      handler(reply);
      return;
    }
    std::shared_ptr<Pending> waiting;
    {
      std::lock_guard lock(mutex);
      if (const auto it = pending.find(reply.id); it != pending.end()) {
        waiting = it->second;
        pending.erase(it);
      } else if (reply.id == 0 && !reply.ok) {
        status.last_error = "device: " + reply.code + " " + reply.text;
      }
    }
    // A reply whose caller has timed out is dropped.
    if (waiting) waiting->outcome.set_value({reply, ""});
  }

  void send_internal(unsigned gen, const std::string& command, std::function<void(const protocol::Reply&)> handler) {
    const std::uint64_t id = next_id++;
    internal[id] = std::move(handler);
    write(gen, std::to_string(id) + " " + command + "\n");
  }

  void write(unsigned gen, std::string line) {
    if (gen != generation || (!socket && !serial)) return;
    write_queue.push_back(std::move(line));
    if (write_queue.size() == 1) write_next(gen);
  }

  void write_next(unsigned gen) {
    with_stream([&](auto& stream) {
      const auto written = [this, gen](boost::system::error_code ec, std::size_t) {
        if (gen != generation) return;
        if (ec) return fail(gen, "write failed: " + ec.message());
        write_queue.pop_front();
        if (!write_queue.empty()) write_next(gen);
      };
      asio::async_write(stream, asio::buffer(write_queue.front()), written);
    });
  }

  void beat(unsigned gen) {
    heartbeat_timer.expires_after(options.heartbeat_interval);
    heartbeat_timer.async_wait([this, gen](boost::system::error_code ec) {
      if (ec || gen != generation) return;
      if (Clock::now() - last_data > options.heartbeat_timeout)
        return fail(gen, "nothing received for " + std::to_string(ms(options.heartbeat_timeout)) +
                             " ms (heartbeat)");
      if (!ping_outstanding) {
        ping_outstanding = true;
        send_internal(gen, "ping", [this](const protocol::Reply&) { ping_outstanding = false; });
      }
      beat(gen);
    });
  }

  // Closes the stream and timers of the current connection.
  void close() {
    boost::system::error_code ignored;
    resolver.cancel();
    if (socket) socket->close(ignored);
    if (serial) serial->close(ignored);
    socket.reset();
    serial.reset();
    connect_timer.cancel();
    heartbeat_timer.cancel();
    lines.clear();
    write_queue.clear();
    internal.clear();
    ping_outstanding = false;
  }

  void notify(bool connected) {
    std::function<void(bool)> f;
    {
      std::lock_guard lock(mutex);
      f = callback;
    }
    if (f) asio::post(notify_io, [f = std::move(f), connected] { f(connected); });
  }

  // Fails every waiting command with `reason`.
  void fail_pending(const std::string& reason) {
    std::map<std::uint64_t, std::shared_ptr<Pending>> failed;
    {
      std::lock_guard lock(mutex);
      failed.swap(pending);
    }
    for (auto& [id, p] : failed) {
      const std::string what =
          "device link to " + endpoint.to_string() + " dropped during \"" + p->what + "\": " + reason;
      p->outcome.set_value({{}, what});
    }
  }

  // The connection of generation `gen` is gone: fail what waits on it, tell
  // the callback if it was up, and try again after the backoff.
  void fail(unsigned gen, const std::string& reason) {
    if (gen != generation) return;
    bool was_up = false;
    bool stop_now = false;
    {
      // With `up`, so a caller that saw the link up holds this connection's
      // generation, never the next one's.
      std::lock_guard lock(mutex);
      ++generation;
      was_up = up;
      up = false;
      status.connected = false;
      status.last_error = "link: " + reason;
      stop_now = stopping;
    }
    close();
    fail_pending(reason);
    if (stop_now) return;
    if (was_up) notify(false);
    reconnect_timer.expires_after(backoff);
    backoff = std::min(options.backoff_max,
                       std::chrono::milliseconds(static_cast<long long>(ms(backoff) * options.backoff_factor)));
    reconnect_timer.async_wait([this](boost::system::error_code ec) {
      if (!ec) connect();
    });
  }

  // --- callers' threads ----------------------------------------------------

  // Sends `command` and waits for its reply: kHalted for an action while
  // halted, kDisconnected if the link is not up or drops, kTimeout after
  // `timeout`, kRefused for an "err".
  protocol::Reply request(const std::string& command, std::chrono::milliseconds timeout, bool actuates = false) {
    const std::uint64_t id = next_id++;
    auto p = std::make_shared<Pending>();
    p->what = command;
    std::future<Outcome> outcome = p->outcome.get_future();
    {
      std::lock_guard lock(mutex);
      if (actuates && halted)
        throw DeviceError(Kind::kHalted, "\"" + command + "\" not sent: the device is halted by an emergency stop");
      if (!up)
        throw DeviceError(Kind::kDisconnected, "device link to " + endpoint.to_string() + " is down; \"" + command +
                                                   "\" not sent" +
                                                   (status.last_error.empty() ? "" : " (" + status.last_error + ")"));
      pending[id] = p;
      // Queued for the wire under the same lock as the halt check, so the
      // wire's order is the order of these decisions (halt_and_vent).
      asio::post(io, [this, gen = generation.load(), line = std::to_string(id) + " " + command + "\n"]() mutable {
        write(gen, std::move(line));
      });
    }
    bool timed_out = false;
    if (outcome.wait_for(timeout) != std::future_status::ready) {
      std::lock_guard lock(mutex);
      // Unless the io thread took it just now (then its outcome follows),
      // give up on it; a late reply will find no one waiting.
      timed_out = pending.erase(id) == 1;
      if (timed_out) status.last_error = "\"" + command + "\" timed out";
    }
    if (timed_out)
      throw DeviceError(Kind::kTimeout, "device command \"" + command + "\" got no reply within " +
                                            std::to_string(ms(timeout)) + " ms");
    return finish(command, outcome.get());
  }

  protocol::Reply finish(const std::string& command, Outcome outcome) {
    if (!outcome.dropped.empty()) throw DeviceError(Kind::kDisconnected, outcome.dropped);
    const protocol::Reply& reply = outcome.reply;
    if (reply.ok) return reply;
    const std::string what = "device refused \"" + command + "\": " + reply.code + ": " + reply.text;
    {
      std::lock_guard lock(mutex);
      status.last_error = what;
    }
    throw DeviceError(reply.code == protocol::error_code_name(protocol::ErrorCode::kCancelled) ? Kind::kVented
                                                                                               : Kind::kRefused,
                      what);
  }
};


}  // namespace hj::device
