// The emulator on the network: accepts protocol connections on TCP and
// feeds their requests, one at a time in arrival order, to an Emulator on
// its own worker thread, while "hello" and "ping" are answered at once (a
// controller keeps its heartbeat while it actuates). It can misbehave on
// purpose for tests (PROTOCOL.md, "Faults").
#pragma once

#include <chrono>
#include <memory>
#include <string>

#include "device/emulator.h"

namespace hj::device {

struct EmulatorServerOptions {
  std::string host = "127.0.0.1";
  unsigned short port = 0;  // 0: the system picks a free one (see port())
  // After answering this many actions, vents and captures (hello, ping,
  // status and fault are not counted), close the connection on the next
  // one without answering it; once. -1: never.
  long drop_after = -1;
};

class EmulatorServer {
 public:
  // Binds and listens (not yet serving). Throws std::runtime_error naming
  // HOST:PORT if it cannot. `emulator` must outlive the server.
  EmulatorServer(Emulator& emulator, EmulatorServerOptions options);
  ~EmulatorServer();  // stops

  unsigned short port() const;
  // Serves from background threads until stop().
  void start();
  void stop();

  // Faults, as the "fault" command gives them: close every connection;
  // hold every device command for `duration`; ignore every line for
  // `duration` (pings included).
  void drop_connections();
  void stall(std::chrono::milliseconds duration);
  void mute(std::chrono::milliseconds duration);

  // Device commands answered so far.
  long commands_answered() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace hj::device
