// The emulator on the network: accepts protocol connections on TCP and
// feeds their device commands, one at a time in arrival order, to an
// Emulator on its own worker thread, while "hello" and "ping" are answered at
// once (a controller keeps its heartbeat while it actuates). A "vent" is a
// controller's safety path: it overtakes the queue and any settle in
// progress, and the emulator vents by itself on silence (its watchdog) or a
// closed connection (PROTOCOL.md, "Vent and watchdog"). It can misbehave on
// purpose for tests (PROTOCOL.md, "Faults").
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "device/emulator.h"

namespace hj::device {

struct EmulatorServerOptions {
  std::string host = "127.0.0.1";
  unsigned short port = 0;  // 0: the system picks a free one (see port())
  // After answering this many actions, vents and captures (hello, ping,
  // status and fault are not counted), close the connection on the next
  // one without answering it; once. -1: never.
  long drop_after = -1;
  // The watchdog: vent by itself after this long without a byte from any
  // connection while the array is actuated (PROTOCOL.md: at most 5 s).
  std::chrono::milliseconds watchdog{2000};
  // Told every vent, with its cause ("vent", "watchdog: ...", "connection closed").
  std::function<void(const std::string& why)> on_vent;
};

// An actuating command as it arrived, for tests that check what the device
// was sent and when.
struct ReceivedAction {
  std::uint64_t sequence = 0;  // from 1, over every action this server received
  std::chrono::steady_clock::time_point at;
  std::string line;
};

struct VentRecord {
  std::chrono::steady_clock::time_point at;
  std::string why;
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
  // The last actions received (at most 100,000) and every vent, oldest first.
  std::vector<ReceivedAction> actions_received() const;
  std::vector<VentRecord> vents() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace hj::device
