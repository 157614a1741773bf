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
};

bool blank(std::string_view line) { return line.find_first_not_of(" \t") == std::string_view::npos; }

}  // namespace

struct EmulatorServer::Impl {
  Impl(Emulator& e, EmulatorServerOptions o) : emulator(e), options(std::move(o)), acceptor(io) {}

  Emulator& emulator;
  const EmulatorServerOptions options;
  asio::io_context io;
  tcp::acceptor acceptor;
  std::thread io_thread;

  // io thread only.
  std::set<std::shared_ptr<Connection>> connections;
  long counted = 0;
  bool dropped_once = false;
  Clock::time_point mute_until{};

  // The device worker: one command at a time.
  std::mutex mutex;
  std::condition_variable wake;
  std::deque<std::function<void()>> jobs;
  Clock::time_point stall_until{};
  bool stopping = false;
  std::thread worker;
  std::atomic<long> answered{0};

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
        if (r.fault.kind == Fault::Kind::kStall) stall(std::chrono::milliseconds(r.fault.ms));
        else mute_until = Clock::now() + std::chrono::milliseconds(r.fault.ms);
        return;
      default: break;
    }
    if (r.command != Command::kStatus) {
      if (options.drop_after >= 0 && !dropped_once && counted == options.drop_after) {
        dropped_once = true;
        return close(c);
      }
      ++counted;
    }
    std::weak_ptr<Connection> weak = c;
    std::lock_guard lock(mutex);
    jobs.push_back([this, weak, r] {
      std::string reply;
      try {
        reply = emulator.handle(r);
      } catch (const std::exception& e) {  // a failure of the device, not of the server
        reply = protocol::format_err(r.id, protocol::ErrorCode::kFailed, e.what());
      }
      ++answered;
      asio::post(io, [this, weak, reply = std::move(reply)] {
        if (const auto c = weak.lock()) write(c, reply);
      });
    });
    wake.notify_all();
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

  void close(const std::shared_ptr<Connection>& c) {
    if (c->closed) return;
    c->closed = true;
    boost::system::error_code ignored;
    c->socket.shutdown(tcp::socket::shutdown_both, ignored);
    c->socket.close(ignored);
    connections.erase(c);
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
      auto job = std::move(jobs.front());
      jobs.pop_front();
      lock.unlock();
      job();
      lock.lock();
    }
  }
};

EmulatorServer::EmulatorServer(Emulator& emulator, EmulatorServerOptions options)
    : impl_(std::make_unique<Impl>(emulator, std::move(options))) {
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
  impl_->worker = std::thread([this] { impl_->work(); });
  impl_->io_thread = std::thread([this] { impl_->io.run(); });
}

void EmulatorServer::stop() {
  if (!impl_->io_thread.joinable()) return;
  asio::post(impl_->io, [this] {
    boost::system::error_code ignored;
    impl_->acceptor.close(ignored);
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

}  // namespace hj::device
