#include "device/emulator.h"

#include <cmath>
#include <limits>
#include <stdexcept>

#include "calib/rasterize.h"
#include "calib/replay.h"

namespace hj::device {

namespace {

CaptureGrid to_capture_grid(const SessionGrid& g) { return {g.nx, g.ny, g.x0_mm, g.y0_mm, g.dx_mm, g.dy_mm}; }

}  // namespace

void CameraOptions::validate() const {
  if (grid.nx < 1 || grid.ny < 1 || static_cast<long>(grid.nx) * grid.ny > protocol::kMaxCaptureSamples)
    throw std::invalid_argument("camera grid of " + std::to_string(grid.nx) + " x " + std::to_string(grid.ny) +
                                " samples: each side must be >= 1 and the total <= " +
                                std::to_string(protocol::kMaxCaptureSamples));
  if (!std::isfinite(grid.x0_mm) || !std::isfinite(grid.y0_mm))
    throw std::invalid_argument("camera grid origin (mm) must be finite");
  if (!(grid.dx_mm > 0.0) || !(grid.dy_mm > 0.0) || !std::isfinite(grid.dx_mm) || !std::isfinite(grid.dy_mm))
    throw std::invalid_argument("camera grid spacing dx, dy (mm) must be positive");
  if (!(noise_mm >= 0.0) || !std::isfinite(noise_mm))
    throw std::invalid_argument("camera noise_mm (sigma, mm) must be finite and >= 0");
  if (!(resolution_mm >= 0.0) || !std::isfinite(resolution_mm))
    throw std::invalid_argument("camera resolution_mm (mm) must be finite and >= 0");
  if (!(dropout >= 0.0 && dropout < 1.0)) throw std::invalid_argument("camera dropout (fraction) must be in [0, 1)");
}

SessionGrid default_capture_grid(const ArrayGeometry& geometry) {
  const double step_mm = 2.0;
  SessionGrid g;
  g.dx_mm = g.dy_mm = step_mm;
  // The floor of a whole number of steps, with room for rounding error.
  g.nx = static_cast<int>(std::floor(geometry.cols * geometry.cell_size_m * 1000.0 / step_mm + 1e-9)) + 1;
  g.ny = static_cast<int>(std::floor(geometry.rows * geometry.cell_size_m * 1000.0 / step_mm + 1e-9)) + 1;
  return g;
}

bool Emulator::SettleLimit::operator()() {
  if (resetting) return false;
  if ((outer && outer()) || (stop && stop())) return true;
  timed_out = std::chrono::steady_clock::now() > deadline;
  return timed_out;
}

EmulatorConfig Emulator::with_settle_limit(EmulatorConfig config, const std::shared_ptr<SettleLimit>& limit) {
  config.camera.validate();
  if (config.settle_timeout.count() <= 0)
    throw std::invalid_argument("emulator settle timeout of " + std::to_string(config.settle_timeout.count()) +
                                " ms: must be positive");
  limit->outer = std::move(config.simulator.interrupted);
  config.simulator.interrupted = [limit] { return (*limit)(); };
  return config;
}

Emulator::Emulator(EmulatorConfig config)
    : config_(with_settle_limit(std::move(config), limit_)),
      simulator_(config_.geometry, config_.params, config_.simulator),
      camera_random_(config_.camera.seed) {}

protocol::Hello Emulator::hello() const {
  protocol::Hello h;
  h.rows = config_.geometry.rows;
  h.cols = config_.geometry.cols;
  h.cell_mm = config_.geometry.cell_size_m * 1000.0;
  h.max_pressure_pa = config_.params.max_pressure_pa;
  h.grid = to_capture_grid(config_.camera.grid);
  return h;
}

std::string Emulator::handle(const protocol::Request& r, std::function<bool()> stop) {
  using protocol::Command;
  limit_->stop = std::move(stop);
  switch (r.command) {
    case Command::kHello: return protocol::format_ok(r.id, protocol::format_hello(hello()));
    case Command::kPing: return protocol::format_ok(r.id);
    case Command::kStatus: return protocol::format_ok(r.id, protocol::format_status(status()));
    case Command::kCapture: return protocol::format_ok(r.id, protocol::format_capture(capture()));
    case Command::kTruth: return protocol::format_ok(r.id, protocol::format_capture(truth()));
    case Command::kVent: return vent(r.id);
    case Command::kAction: return act(r.id, r.action, std::chrono::steady_clock::now() + config_.settle_timeout);
    case Command::kFault: break;
  }
  return protocol::format_err(r.id, protocol::ErrorCode::kFailed, "faults are handled by the server, not the device");
}

std::string Emulator::act(std::uint64_t id, const Action& action, std::chrono::steady_clock::time_point deadline) {
  limit_->deadline = deadline;
  limit_->timed_out = false;
  try {
    simulator_.apply(action);
  } catch (const SettleInterrupted&) {
    const std::string why = limit_->timed_out
                                ? "the membrane did not settle within " +
                                      std::to_string(config_.settle_timeout.count()) + " ms (the settle timeout)"
                                : "stopped by a vent";
    return protocol::format_err(id, protocol::ErrorCode::kFailed,
                                action.describe() + ": " + why + "; the state is as before the action");
  } catch (const std::invalid_argument& e) {
    const auto code = action.op == Action::Op::kSetPressure ? protocol::ErrorCode::kUnsafe
                                                            : protocol::ErrorCode::kOutOfRange;
    return protocol::format_err(id, code, e.what());
  } catch (const std::exception& e) {
    return protocol::format_err(id, protocol::ErrorCode::kFailed, action.describe() + ": " + e.what());
  }
  return protocol::format_ok(id);
}

// The safe state, one action at a time as a controller would: every pin
// released, every cell unjammed, then the chamber vented. Both orders end
// in the rest state, but this one settles far faster in the simulator
// (venting first drags jammed plates and pinned nodes through the sag).
std::string Emulator::vent(std::uint64_t id) {
  const Mesh& mesh = simulator_.mesh();
  std::vector<Action> steps;
  for (int a = 1; a < mesh.rows(); ++a)
    for (int b = 1; b < mesh.cols(); ++b)
      if (simulator_.state().pinned(mesh, a, b)) steps.push_back(Action::unpin(a, b));
  for (int r = 0; r < mesh.rows(); ++r)
    for (int c = 0; c < mesh.cols(); ++c)
      if (simulator_.state().jammed(mesh, r, c)) steps.push_back(Action::unjam(r, c));
  steps.push_back(Action::set_pressure(0.0));
  limit_->stop = {};  // a vent is not itself stopped
  // A quarter of an action's time, then the reset: a command queued behind
  // the vent still gets its answer within the link's reply timeout.
  const auto deadline = std::chrono::steady_clock::now() + config_.settle_timeout / 4;
  for (const Action& step : steps)
    if (act(id, step, deadline).rfind("err", 0) == 0) {
      // The membrane did not settle on the way down: venting ends at rest all the same.
      reset_to_rest();
      break;
    }
  return protocol::format_ok(id);
}

void Emulator::reset_to_rest() {
  // Cleared on every way out, so a throwing constructor cannot leave settles uninterruptible.
  struct Resetting {
    SettleLimit& limit;
    explicit Resetting(SettleLimit& l) : limit(l) { limit.resetting = true; }
    ~Resetting() { limit.resetting = false; }
  } resetting(*limit_);
  simulator_ = Simulator(config_.geometry, config_.params, config_.simulator);
}

protocol::StatusPayload Emulator::status() const {
  const Mesh& mesh = simulator_.mesh();
  const DeviceState& state = simulator_.state();
  protocol::StatusPayload s;
  s.pressure_pa = state.pressure_pa;
  s.cell_jammed = state.cell_jammed;
  // Every corner of the array, (rows+1) x (cols+1); only inner ones pin.
  s.node_pinned.assign(static_cast<std::size_t>(mesh.rows() + 1) * (mesh.cols() + 1), 0);
  for (int a = 1; a < mesh.rows(); ++a)
    for (int b = 1; b < mesh.cols(); ++b) s.node_pinned[a * (mesh.cols() + 1) + b] = state.pinned(mesh, a, b);
  return s;
}

Eigen::MatrixXd Emulator::exact_frame() const {
  return rasterize_top_view(simulator_.mesh(), simulator_.state().x, config_.camera.grid);
}

Eigen::MatrixXd Emulator::camera_frame() const {
  Eigen::MatrixXd heights = exact_frame();
  simulator_.model().adjust_measurement(sample_x_mm(config_.camera.grid), sample_y_mm(config_.camera.grid), heights);
  return heights;
}

Capture Emulator::truth() const {
  Capture c;
  c.grid = to_capture_grid(config_.camera.grid);
  c.heights_mm = exact_frame();
  return c;
}

Capture Emulator::capture() {
  const CameraOptions& cam = config_.camera;
  Capture c;
  c.grid = to_capture_grid(cam.grid);
  c.heights_mm = camera_frame();
  std::normal_distribution<double> noise(0.0, cam.noise_mm);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  for (Eigen::Index i = 0; i < c.heights_mm.size(); ++i) {
    double& h = c.heights_mm.data()[i];
    if (std::isnan(h)) continue;
    if (cam.noise_mm > 0.0) h += noise(camera_random_);
    if (cam.resolution_mm > 0.0) h = std::round(h / cam.resolution_mm) * cam.resolution_mm + 0.0;  // no "-0"
    if (cam.dropout > 0.0 && uniform(camera_random_) < cam.dropout) h = std::numeric_limits<double>::quiet_NaN();
  }
  return c;
}

}  // namespace hj::device
