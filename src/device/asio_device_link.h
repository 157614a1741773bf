// The real device link: the line protocol of src/device/PROTOCOL.md over TCP
// or a serial port, run by one Boost.Asio thread. It says hello and reads the
// device's state on connect, sends a ping every heartbeat_interval (no reply
// line for heartbeat_timeout = link down), reconnects with capped
// exponential backoff, and fails every command in flight with
// DeviceError(kDisconnected) the moment the link drops. It never re-sends a
// command on its own. Asio stays behind the Impl so that this header, like
// device_link.h, can be included by the server without it.
#pragma once

#include <chrono>
#include <memory>
#include <string>

#include "device/device_link.h"
#include "device/link_options.h"

namespace hj::device {

class AsioDeviceLink final : public DeviceLink {
 public:
  // Throws std::invalid_argument naming a bad option.
  AsioDeviceLink(Endpoint endpoint, LinkOptions options = {});
  ~AsioDeviceLink() override;  // stops

  void start() override;
  void stop() override;
  bool connected() const override;

  void execute(const Action& action, std::chrono::milliseconds timeout) override;
  Capture capture(std::chrono::milliseconds timeout) override;
  void vent(std::chrono::milliseconds timeout) override;
  // The device's state as last reported or acknowledged (no I/O);
  // last_error is the most recent failure (kept after a reconnect).
  DeviceStatus status() const override;
  void halt_and_vent(std::chrono::milliseconds timeout) override;
  void release_halt() override;
  // Callbacks run in order on a thread of the link's own (not the one doing
  // I/O), so one may send commands itself, e.g. vent() on reconnect; it must
  // not call stop().
  void on_connection_change(std::function<void(bool connected)> callback) override;

  // Asks the device for its state ("status"), refreshes status() and
  // returns it.
  DeviceStatus query_status(std::chrono::milliseconds timeout);
  // One "ping" round trip.
  void ping(std::chrono::milliseconds timeout);
  // Sends one command line without its id (e.g. "fault stall 500") and
  // returns the payload of its "ok" reply: for tools and tests. Throws
  // DeviceError like the others.
  std::string send_raw(const std::string& command, std::chrono::milliseconds timeout);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace hj::device
