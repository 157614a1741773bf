// An in-process stand-in for the array's controller (device/device_link.h),
// for server tests: records what it was told to do, can hold each command
// until the test lets it go, and can drop and restore the connection.
#pragma once

#include <condition_variable>
#include <mutex>
#include <string>
#include <vector>

#include "device/device_link.h"

namespace hj::testing_support {

class FakeDeviceLink final : public device::DeviceLink {
 public:
  FakeDeviceLink(int rows = 3, int cols = 4, double max_pressure_pa = 3450.0)
      : rows_(rows), cols_(cols), max_pressure_pa_(max_pressure_pa) {}

  void start() override {
    set_connected(true);
  }
  void stop() override {
    std::lock_guard lock(mutex_);
    callback_ = nullptr;
    stopped_ = true;
    changed_.notify_all();
  }
  bool connected() const override {
    std::lock_guard lock(mutex_);
    return connected_;
  }

  void execute(const Action& action, std::chrono::milliseconds timeout) override {
    std::unique_lock lock(mutex_);
    wait_for_turn(lock, timeout, action.describe());
    if (halted_) throw device::DeviceError(device::DeviceError::Kind::kHalted, action.describe() + ": halted");
    log_.push_back(action.describe());
    if (action.op == Action::Op::kSetPressure) pressure_pa_ = action.pressure_pa;
  }
  device::Capture capture(std::chrono::milliseconds timeout) override {
    std::unique_lock lock(mutex_);
    wait_for_turn(lock, timeout, "capture");
    log_.push_back("capture");
    device::Capture c;
    c.grid = {3, 2, 0.0, 0.0, 10.0, 10.0};
    c.heights_mm = Eigen::MatrixXd::Constant(2, 3, pressure_pa_ / 100.0);
    return c;
  }
  void vent(std::chrono::milliseconds) override {
    std::lock_guard lock(mutex_);
    if (!connected_) throw device::DeviceError(device::DeviceError::Kind::kDisconnected, "vent: link down");
    log_.push_back("vent");
    pressure_pa_ = 0.0;
    ++vents_;
    changed_.notify_all();
  }
  void halt_and_vent(std::chrono::milliseconds timeout) override {
    {
      std::lock_guard lock(mutex_);
      halted_ = true;
      changed_.notify_all();
    }
    vent(timeout);
  }
  void release_halt() override {
    std::lock_guard lock(mutex_);
    halted_ = false;
  }
  device::DeviceStatus status() const override {
    std::lock_guard lock(mutex_);
    device::DeviceStatus s;
    s.connected = connected_;
    s.endpoint = "fake";
    s.rows = rows_, s.cols = cols_;
    s.cell_mm = 38.0;
    s.pressure_pa = pressure_pa_;
    s.max_pressure_pa = max_pressure_pa_;
    s.cell_jammed.assign(size_t(rows_ * cols_), 0);
    s.node_pinned.assign(size_t((rows_ + 1) * (cols_ + 1)), 0);
    return s;
  }
  void on_connection_change(std::function<void(bool)> callback) override {
    std::lock_guard lock(mutex_);
    callback_ = std::move(callback);
  }

  // Test controls.
  // Holds every action and capture until release() lets `n` more through.
  void hold() {
    std::lock_guard lock(mutex_);
    holding_ = true;
    permits_ = 0;
  }
  void release(int n = 1'000'000) {
    std::lock_guard lock(mutex_);
    permits_ += n;
    changed_.notify_all();
  }
  void free_run() {
    std::lock_guard lock(mutex_);
    holding_ = false;
    changed_.notify_all();
  }
  // Drops (false) or restores (true) the connection; a held command fails.
  void set_connected(bool connected) {
    std::function<void(bool)> callback;
    {
      std::lock_guard lock(mutex_);
      connected_ = connected;
      callback = callback_;
      changed_.notify_all();
    }
    if (callback) callback(connected);
  }
  std::vector<std::string> log() const {
    std::lock_guard lock(mutex_);
    return log_;
  }
  int vents() const {
    std::lock_guard lock(mutex_);
    return vents_;
  }
  // Number of commands waiting in hold().
  int waiting() const {
    std::lock_guard lock(mutex_);
    return waiting_;
  }

 private:
  void wait_for_turn(std::unique_lock<std::mutex>& lock, std::chrono::milliseconds timeout, const std::string& what) {
    if (!connected_) throw device::DeviceError(device::DeviceError::Kind::kDisconnected, what + ": link down");
    ++waiting_;
    const bool ok = changed_.wait_for(lock, timeout, [&] { return !connected_ || stopped_ || !holding_ || permits_ > 0; });
    --waiting_;
    if (!ok) throw device::DeviceError(device::DeviceError::Kind::kTimeout, what + ": no acknowledgement");
    if (!connected_ || stopped_) throw device::DeviceError(device::DeviceError::Kind::kDisconnected, what + ": link dropped");
    if (holding_) --permits_;
  }

  const int rows_, cols_;
  const double max_pressure_pa_;
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  bool connected_ = false, stopped_ = false, holding_ = false, halted_ = false;
  int permits_ = 0, waiting_ = 0, vents_ = 0;
  double pressure_pa_ = 0.0;
  std::vector<std::string> log_;
  std::function<void(bool)> callback_;
};

}  // namespace hj::testing_support
