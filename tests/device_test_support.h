// An emulated 3 x 4 array served on a loopback port chosen by the system,
// and waiting helpers bounded so a broken link fails a test instead of
// hanging it. Shared by the device tests and the device benchmark.
#pragma once

#include <chrono>
#include <condition_variable>
#include <functional>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

#include "device/emulator.h"
#include "device/emulator_server.h"

namespace hj::testing_support {

inline device::EmulatorConfig emulator_config_3x4() {
  device::EmulatorConfig config;
  config.geometry = {3, 4, 0.038, 4};
  config.params = SurfaceParameters::paper_defaults(config.geometry);
  config.camera.grid = device::default_capture_grid(config.geometry);
  return config;
}

struct EmulatedDevice {
  explicit EmulatedDevice(device::EmulatorServerOptions options = {},
                          device::EmulatorConfig config = emulator_config_3x4())
      : emulator(std::move(config)), server(emulator, options) {
    server.start();
  }
  std::string endpoint() const { return "127.0.0.1:" + std::to_string(server.port()); }

  device::Emulator emulator;
  device::EmulatorServer server;
};

// Polls `condition` until it holds or `limit` passes; returns whether it held.
inline bool eventually(const std::function<bool()>& condition,
                       std::chrono::milliseconds limit = std::chrono::milliseconds(10000)) {
  const auto end = std::chrono::steady_clock::now() + limit;
  while (!condition()) {
    if (std::chrono::steady_clock::now() > end) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  return true;
}

// Records on_connection_change calls.
class ConnectionEvents {
 public:
  std::function<void(bool)> callback() {
    return [this](bool up) {
      std::lock_guard lock(mutex_);
      events_.push_back(up);
    };
  }
  std::vector<bool> events() const {
    std::lock_guard lock(mutex_);
    return events_;
  }
  // Waits until `count` events have arrived.
  bool reach(std::size_t count) {
    return eventually([&] { return events().size() >= count; });
  }

 private:
  mutable std::mutex mutex_;
  std::vector<bool> events_;
};

}  // namespace hj::testing_support
