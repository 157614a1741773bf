// The emulated array behind the device protocol: a Simulator standing in
// for membrane and controller, and a depth camera that rasterises the
// settled surface onto the session grid (src/calib/rasterize.h) with the
// Gaussian noise, rounding and dropped samples of the shared sessions
// (data/sessions/*/README.md). It answers one request at a time; the
// network side is EmulatorServer.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <random>
#include <string>

#include "calib/session.h"
#include "device/protocol.h"
#include "sim/simulator.h"

namespace hj::device {

struct CameraOptions {
  SessionGrid grid;            // where captures sample, mm
  double noise_mm = 0.0;       // Gaussian sigma added to each height
  double resolution_mm = 0.0;  // heights rounded to a multiple of this; 0 = exact
  double dropout = 0.0;        // fraction of samples reported as NaN, [0, 1)
  std::uint64_t seed = 1;      // of the camera's random generator

  // Throws std::invalid_argument naming the field (and unit) that is wrong.
  void validate() const;
};

// The shared sessions' grid for an array: 2 mm samples from (0, 0) covering
// it (77 x 58 for 3 x 4 cells of 38 mm).
SessionGrid default_capture_grid(const ArrayGeometry& geometry);

struct EmulatorConfig {
  ArrayGeometry geometry;
  SurfaceParameters params;  // params.max_pressure_pa is the device's limit
  SimulatorOptions simulator;
  CameraOptions camera;
  // The longest one action's settle may take before the emulator answers
  // "failed" with the state as before the action: a device answers within
  // the link's reply timeout (60 s) even where the model has no equilibrium
  // it can find. Must be positive.
  std::chrono::milliseconds settle_timeout{30000};
};

class Emulator {
 public:
  // Builds and settles the simulator at rest. Throws std::invalid_argument
  // on a bad geometry, parameter, effect or camera option.
  explicit Emulator(EmulatorConfig config);

  protocol::Hello hello() const;
  // The reply line to a hello, status, capture, vent or action request:
  // "ok ID ..." or "err ID CODE message" (out_of_range, unsafe, failed).
  // `stop`, polled while settling, ends an action's settle early (answered
  // "failed", the state as it was): a vent that overtakes it.
  std::string handle(const protocol::Request& request, std::function<bool()> stop = {});

  const Simulator& simulator() const { return simulator_; }
  // The true surface on the camera grid, mm: no measurement effect (a tilted
  // camera), no noise. The "truth" command's answer.
  Eigen::MatrixXd exact_frame() const;
  // What a capture sees before noise: the true surface as the measurement
  // effects of the emulator's params (sensor_tilt) change it.
  Eigen::MatrixXd camera_frame() const;

 private:
  std::string act(std::uint64_t id, const Action& action, std::chrono::steady_clock::time_point deadline);
  std::string vent(std::uint64_t id);
  // The rest state at once, as venting ends (nothing jammed or pinned, P = 0).
  void reset_to_rest();
  protocol::StatusPayload status() const;
  Capture capture();
  Capture truth() const;

  // What the simulator's interrupted callback reads: the current action's
  // deadline and stop. Shared, so a moved emulator's simulator still sees it.
  struct SettleLimit {
    std::function<bool()> outer;  // the config's own SimulatorOptions::interrupted
    std::chrono::steady_clock::time_point deadline = std::chrono::steady_clock::time_point::max();
    std::function<bool()> stop;
    bool timed_out = false;
    bool resetting = false;  // the rest settle of a reset is never cut short
    bool operator()();
  };
  static EmulatorConfig with_settle_limit(EmulatorConfig config, const std::shared_ptr<SettleLimit>& limit);

  std::shared_ptr<SettleLimit> limit_ = std::make_shared<SettleLimit>();
  EmulatorConfig config_;
  Simulator simulator_;
  std::mt19937_64 camera_random_;
};

}  // namespace hj::device
