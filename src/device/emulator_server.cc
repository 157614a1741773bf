#include "device/emulator_server.h"

#include <array>
#include <atomic>
// Boost 1.74's asio/awaitable.hpp uses std::exchange without <utility>.
#include <utility>
// clang-format off
#include <boost/asio.hpp>
// clang-format on
#include <condition_variable>
#include <deque>
#include <functional>
#include <mutex>
#include <set>
#include <thread>

#include "device/line_buffer.h"

namespace hj::device {

namespace asio = boost::asio;
using asio::ip::tcp;
using Clock = std::chrono::steady_clock;

namespace {

struct Connection {
  explicit Connection(tcp::socket s) : socket(std::move(s)) {}
  tcp::socket socket;
  LineBuffer lines{protocol::kMaxRequestBytes};
  std::array<char, 4096> buffer{};
  std::deque<std::string> out;
  bool closed = false;
  bool actuated = false;  // it sent an action since the last vent (io thread)
};

// A device command for the worker. Without a connection it is the
// membrane's part of a vent (the actuators were released at once).
struct DeviceCommand {
  std::weak_ptr<Connection> connection;
  protocol::Request request;
  bool answers = true;
  bool overtaken = false;  // a vent came while it ran: answered "cancelled"
  bool refused = false;    // `fault refuse` picked it: answered "failed", not carried out
};

bool blank(std::string_view line) { return line.find_first_not_of(" \t") == std::string_view::npos; }

constexpr std::size_t kMaxActionLog = 100'000;

// The request as sent, without its id: "set_pressure 900".
std::string command_text(const protocol::Request& r) {
  const std::string line = protocol::format_request(r);
  return line.substr(line.find(' ') + 1);
}

std::string overtaken_message(const protocol::Request& r, const std::string& why) {
  return "\"" + command_text(r) + "\" not carried out: the device vented (" + why + ")";
}

}  // namespace

struct EmulatorServer::Impl {
  Impl(Emulator& e, EmulatorServerOptions o)
      : emulator(e), options(std::move(o)), acceptor(io), watchdog_timer(io) {}

  Emulator& emulator;
  const EmulatorServerOptions options;
  asio::io_context io;
  tcp::acceptor acceptor;
  asio::steady_timer watchdog_timer;
  std::thread io_thread;

  // io thread only.
  std::set<std::shared_ptr<Connection>> connections;
  long counted = 0;
  bool dropped_once = false;
  Clock::time_point mute_until{};
  int refuse_in = 0;  // `fault refuse N`: the action this many from now is refused; 0 none
  Clock::time_point last_heard = Clock::now();

  // The device worker: one command at a time.
  mutable std::mutex mutex;
  std::condition_variable wake;
  std::deque<std::shared_ptr<DeviceCommand>> jobs;
  std::shared_ptr<DeviceCommand> current;  // the command the worker is carrying out
  bool actuated = false;                   // an action arrived since the last vent
  Clock::time_point stall_until{};
  bool stopping = false;
  std::thread worker;
  std::atomic<long> answered{0};
  std::deque<ReceivedAction> action_log;
  std::uint64_t actions_seen = 0;
  std::vector<VentRecord> vent_log;

  void accept() {
    acceptor.async_accept([this](boost::system::error_code ec, tcp::socket socket) {
      if (ec == asio::error::operation_aborted || !acceptor.is_open()) return;
      if (!ec) {
        socket.set_option(tcp::no_delay(true), ec);
        auto c = std::make_shared<Connection>(std::move(socket));
        connections.insert(c);
        read(c);
      }
      accept();
    });
  }

  void read(const std::shared_ptr<Connection>& c) {
    c->socket.async_read_some(asio::buffer(c->buffer), [this, c](boost::system::error_code ec, std::size_t n) {
      if (c->closed) return;
      if (ec) return close(c);
      last_heard = Clock::now();
      c->lines.feed(
          std::string_view(c->buffer.data(), n), [&](std::string_view line) { received(c, line); },
          [&] {
            write(c, protocol::format_err(0, protocol::ErrorCode::kTooLong,
                                          "line exceeds " + std::to_string(protocol::kMaxRequestBytes) + " bytes"));
          });
      if (!c->closed) read(c);
    });
  }

  void received(const std::shared_ptr<Connection>& c, std::string_view line) {
    if (c->closed || Clock::now() < mute_until || blank(line)) return;
    protocol::Request r;
    try {
      r = protocol::parse_request(line);
    } catch (const protocol::ProtocolError& e) {
      return write(c, protocol::format_err(e.id(), e.code(), e.what()));
    }
    using protocol::Command;
    using Fault = protocol::Fault;
    switch (r.command) {
      case Command::kHello: return write(c, protocol::format_ok(r.id, protocol::format_hello(emulator.hello())));
      case Command::kPing: return write(c, protocol::format_ok(r.id));
      case Command::kStatus: break;
      case Command::kFault:
        if (r.fault.kind == Fault::Kind::kDrop) return close(c);
        write(c, protocol::format_ok(r.id));
        if (r.fault.kind == Fault::Kind::kRefuse) refuse_in = r.fault.actions;
        if (r.fault.kind == Fault::Kind::kStall) stall(std::chrono::milliseconds(r.fault.ms));
        else mute_until = Clock::now() + std::chrono::milliseconds(r.fault.ms);
        return;
      default: break;
    }
    if (r.command != Command::kStatus && r.command != Command::kTruth) {
      if (options.drop_after >= 0 && !dropped_once && counted == options.drop_after) {
        dropped_once = true;
        return close(c);
      }
      ++counted;
    }
    if (r.command == Command::kVent) {
      vent_at_once("vent");
      ++answered;
      return write(c, protocol::format_ok(r.id));
    }
    auto command = std::make_shared<DeviceCommand>();
    command->connection = c;
    command->request = r;
    if (r.command == Command::kAction) c->actuated = true;
    if (r.command == Command::kAction && refuse_in > 0) command->refused = --refuse_in == 0;
    std::lock_guard lock(mutex);
    if (r.command == Command::kAction) record_action(line);
    jobs.push_back(std::move(command));
    wake.notify_all();
  }

  // With `mutex` held.
  void record_action(std::string_view line) {
    actuated = true;
    action_log.push_back({++actions_seen, Clock::now(), std::string(line)});
    if (action_log.size() > kMaxActionLog) action_log.pop_front();
  }

  // The controller's safety path (io thread): every actuator is released
  // now; commands not yet begun, and one in progress, are answered
  // "cancelled"; the membrane relaxes on the worker before anything else.
  void vent_at_once(const std::string& why) {
    for (const auto& c : connections) c->actuated = false;
    std::deque<std::shared_ptr<DeviceCommand>> overtaken;
    {
      std::lock_guard lock(mutex);
      overtaken.swap(jobs);
      if (current) current->overtaken = true;
      auto relax = std::make_shared<DeviceCommand>();
      relax->request.command = protocol::Command::kVent;
      relax->answers = false;
      jobs.push_back(std::move(relax));
      actuated = false;
      vent_log.push_back({Clock::now(), why});
      wake.notify_all();
    }
    for (const auto& command : overtaken)
      if (const auto c = command->connection.lock(); c && command->answers)
        write(c, protocol::format_err(command->request.id, protocol::ErrorCode::kCancelled,
                                      overtaken_message(command->request, why)));
    if (options.on_vent) options.on_vent(why);
  }

  void watch() {
    const auto period = std::max(std::chrono::milliseconds(10), options.watchdog / 10);
    watchdog_timer.expires_after(period);
    watchdog_timer.async_wait([this](boost::system::error_code ec) {
      if (ec) return;
      bool armed = false;
      {
        std::lock_guard lock(mutex);
        armed = actuated;
      }
      if (armed && Clock::now() - last_heard > options.watchdog)
        vent_at_once("watchdog: nothing heard for " + std::to_string(options.watchdog.count()) + " ms");
      watch();
    });
  }

  void write(const std::shared_ptr<Connection>& c, const std::string& line) {
    if (c->closed) return;
    c->out.push_back(line + "\n");
    if (c->out.size() == 1) write_next(c);
  }

  void write_next(const std::shared_ptr<Connection>& c) {
    asio::async_write(c->socket, asio::buffer(c->out.front()), [this, c](boost::system::error_code ec, std::size_t) {
      if (c->closed) return;
      if (ec) return close(c);
      c->out.pop_front();
      if (!c->out.empty()) write_next(c);
    });
  }

  // A closed connection counts as silence: if it actuated the array since
  // the last vent, the array vents at once (and nothing it queued is
  // carried out). Another connection closing (a tool's) changes nothing.
  void close(const std::shared_ptr<Connection>& c) {
    if (c->closed) return;
    c->closed = true;
    boost::system::error_code ignored;
    c->socket.shutdown(tcp::socket::shutdown_both, ignored);
    c->socket.close(ignored);
    connections.erase(c);
    if (c->actuated) vent_at_once("connection closed");
  }

  void stall(std::chrono::milliseconds duration) {
    std::lock_guard lock(mutex);
    stall_until = std::max(stall_until, Clock::now() + duration);
    wake.notify_all();
  }

  void work() {
    std::unique_lock lock(mutex);
    while (true) {
      wake.wait(lock, [&] { return stopping || !jobs.empty(); });
      if (stopping) return;
      // A stall holds commands (they are answered when it ends).
      while (!stopping && Clock::now() < stall_until) wake.wait_until(lock, stall_until);
      if (stopping) return;
      if (jobs.empty()) continue;  // a vent answered them while the stall held them
      current = std::move(jobs.front());
      jobs.pop_front();
      lock.unlock();
      carry_out(*current);
      lock.lock();
      const std::shared_ptr<DeviceCommand> done = std::move(current);
      current.reset();
      if (!done->answers) continue;
      const protocol::Request& r = done->request;
      std::string reply = done->overtaken ? protocol::format_err(r.id, protocol::ErrorCode::kCancelled,
                                                                 overtaken_message(r, "a vent came during it"))
                                          : std::move(last_reply);
      ++answered;
      asio::post(io, [this, weak = done->connection, reply = std::move(reply)] {
        if (const auto c = weak.lock()) write(c, reply);
      });
    }
  }

  std::string last_reply;  // worker thread only

  void carry_out(const DeviceCommand& command) {
    if (command.refused) {
      last_reply = protocol::format_err(command.request.id, protocol::ErrorCode::kFailed,
                                        command_text(command.request) +
                                            ": refused (fault refuse); the state is as before it");
      return;
    }
    try {
      // A vent that overtakes the command, or the server stopping, ends its settle.
      last_reply = emulator.handle(command.request, [this, &command] {
        std::lock_guard lock(mutex);
        return stopping || command.overtaken;
      });
    } catch (const std::exception& e) {  // a failure of the device, not of the server
      last_reply = protocol::format_err(command.request.id, protocol::ErrorCode::kFailed, e.what());
    }
  }
};

EmulatorServer::EmulatorServer(Emulator& emulator, EmulatorServerOptions options)
    : impl_(std::make_unique<Impl>(emulator, std::move(options))) {
  const auto watchdog = impl_->options.watchdog;
  if (watchdog < std::chrono::milliseconds(10) || watchdog > std::chrono::milliseconds(5000))
    throw std::invalid_argument("emulator watchdog of " + std::to_string(watchdog.count()) +
                                " ms: must be within 10..5000 ms");
  const std::string where = impl_->options.host + ":" + std::to_string(impl_->options.port);
  try {
    tcp::resolver resolver(impl_->io);
    const auto endpoints = resolver.resolve(impl_->options.host, std::to_string(impl_->options.port),
                                            tcp::resolver::passive);
    const tcp::endpoint endpoint = endpoints.begin()->endpoint();
    impl_->acceptor.open(endpoint.protocol());
    impl_->acceptor.set_option(tcp::acceptor::reuse_address(true));
    impl_->acceptor.bind(endpoint);
    impl_->acceptor.listen();
  } catch (const boost::system::system_error& e) {
    throw std::runtime_error("cannot listen on " + where + ": " + e.code().message());
  }
}

EmulatorServer::~EmulatorServer() { stop(); }

unsigned short EmulatorServer::port() const { return impl_->acceptor.local_endpoint().port(); }

void EmulatorServer::start() {
  if (impl_->io_thread.joinable()) return;
  impl_->accept();
  impl_->watch();
  impl_->worker = std::thread([this] { impl_->work(); });
  impl_->io_thread = std::thread([this] { impl_->io.run(); });
}

void EmulatorServer::stop() {
  if (!impl_->io_thread.joinable()) return;
  asio::post(impl_->io, [this] {
    boost::system::error_code ignored;
    impl_->acceptor.close(ignored);
    impl_->watchdog_timer.cancel();
    for (const auto& c : std::set<std::shared_ptr<Connection>>(impl_->connections)) impl_->close(c);
    impl_->io.stop();
  });
  impl_->io_thread.join();
  {
    std::lock_guard lock(impl_->mutex);
    impl_->stopping = true;
    impl_->wake.notify_all();
  }
  impl_->worker.join();
}

void EmulatorServer::drop_connections() {
  asio::post(impl_->io, [this] {
    for (const auto& c : std::set<std::shared_ptr<Connection>>(impl_->connections)) impl_->close(c);
  });
}

void EmulatorServer::stall(std::chrono::milliseconds duration) { impl_->stall(duration); }

void EmulatorServer::mute(std::chrono::milliseconds duration) {
  asio::post(impl_->io, [this, duration] { impl_->mute_until = Clock::now() + duration; });
}

long EmulatorServer::commands_answered() const { return impl_->answered; }

std::vector<ReceivedAction> EmulatorServer::actions_received() const {
  std::lock_guard lock(impl_->mutex);
  return {impl_->action_log.begin(), impl_->action_log.end()};
}

std::vector<VentRecord> EmulatorServer::vents() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->vent_log;
}

}  // namespace hj::device
