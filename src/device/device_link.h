// The attached array as the server sees it: a link to its controller
// (docs/architecture.md, layer 4). The real link speaks the line protocol of
// src/device/PROTOCOL.md over TCP or a serial port (Boost.Asio); tests may
// substitute an in-process fake. This header is the contract between the
// device layer and the server; keep it free of Asio and gRPC types.
#pragma once

#include <Eigen/Core>
#include <chrono>
#include <functional>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "model/action.h"

namespace hj::device {

// A command the device refused or could not finish: a timeout, a dropped
// link, an error the controller reported, a command the device dropped
// because it vented first (kVented: a stop or its watchdog), or an action
// not sent because the link is halted (an emergency stop). what() names the
// command.
class DeviceError : public std::runtime_error {
 public:
  enum class Kind { kTimeout, kDisconnected, kRefused, kVented, kHalted };
  DeviceError(Kind kind, const std::string& what) : std::runtime_error(what), kind_(kind) {}
  Kind kind() const { return kind_; }

 private:
  Kind kind_;
};

// Where a depth-camera capture samples the surface (docs/session-format.md).
struct CaptureGrid {
  int nx = 0, ny = 0;
  double x0_mm = 0.0, y0_mm = 0.0, dx_mm = 1.0, dy_mm = 1.0;
};

struct Capture {
  CaptureGrid grid;
  Eigen::MatrixXd heights_mm;  // (ny x nx), NaN = not seen
};

struct DeviceStatus {
  bool connected = false;
  std::string endpoint;          // "127.0.0.1:7700" or "/dev/ttyUSB0"
  int rows = 0, cols = 0;        // the array, as the controller reports it
  double cell_mm = 0.0;          // its cell side
  double pressure_pa = 0.0;
  double max_pressure_pa = 0.0;  // the device's own limit
  std::vector<char> cell_jammed;  // rows * cols, row-major
  std::vector<char> node_pinned;  // (rows + 1) * (cols + 1), row-major
  std::optional<Capture> last_capture;
  std::string last_error;         // empty if none
};

class DeviceLink {
 public:
  virtual ~DeviceLink() = default;

  // Starts connecting in the background (reconnecting with backoff after a
  // drop) and returns at once.
  virtual void start() = 0;
  // Closes the link; no callbacks after it returns.
  virtual void stop() = 0;
  virtual bool connected() const = 0;

  // Each sends one command and waits for its acknowledgement (the settle of
  // the device included). Throw DeviceError on timeout, drop or refusal.
  virtual void execute(const Action& action, std::chrono::milliseconds timeout) = 0;
  virtual Capture capture(std::chrono::milliseconds timeout) = 0;
  // The safe state: pressure 0, every cell unjammed, every node unpinned.
  virtual void vent(std::chrono::milliseconds timeout) = 0;
  virtual DeviceStatus status() const = 0;

  // The emergency stop, as one decision: from the moment it is called every
  // execute() is refused unsent (DeviceError kHalted) until release_halt(),
  // and a vent goes out behind whatever was already sent, so no action
  // reaches the device after the vent. Waits for the vent's answer; throws
  // DeviceError like vent() (the halt stays in place either way).
  virtual void halt_and_vent(std::chrono::milliseconds timeout) = 0;
  virtual void release_halt() = 0;

  // Called from the link's thread whenever the connection comes up or goes
  // down (true = connected). Set before start().
  virtual void on_connection_change(std::function<void(bool connected)> callback) = 0;
};

}  // namespace hj::device
