#include "device/emulator_options.h"

#include <charconv>
#include <cmath>
#include <optional>
#include <stdexcept>

#include "calib/model_params.h"

namespace hj::device {

const char* const kEmulatorUsage =
    "usage: hapticjam-device-emulator --listen HOST:PORT [options]\n"
    "Stands in for a Haptic Jamming array: speaks the device protocol\n"
    "(src/device/PROTOCOL.md) on TCP, runs the simulator for every action and\n"
    "answers captures with height frames on the session grid (mm).\n"
    "  --listen HOST:PORT     where to listen; port 0 picks a free one (printed)\n"
    "  --rows R --cols C      cells of the array (default 3 x 4)\n"
    "  --segments P           mesh segments per cell edge, 2..64 (default 4)\n"
    "  --cell-mm MM           cell side (default 38)\n"
    "  --params FILE          model parameters and effects (hapticjam.params/1), e.g.\n"
    "                         a device the planner does not know; a measurement\n"
    "                         effect (sensor_tilt) changes the captures only\n"
    "  --effects a,b          switch on extra effects by name, default values\n"
    "  --max-pressure-kpa K   the device's pressure limit (default 3.45)\n"
    "  --grid nx,ny,x0,y0,dx,dy  capture grid in mm (default: 2 mm covering\n"
    "                         the array, e.g. 77,58,0,0,2,2 for 3 x 4 x 38 mm)\n"
    "  --noise-mm SIGMA       (or --camera-noise-mm) Gaussian camera noise; as in the shared sessions it\n"
    "                         also rounds to 1 mm and drops 1 % of the samples,\n"
    "                         unless --resolution-mm / --dropout say otherwise\n"
    "                         (default 0: exact frames)\n"
    "  --resolution-mm MM     round heights to this (0 = exact)\n"
    "  --dropout FRACTION     share of samples reported as nan, [0, 1)\n"
    "  --seed N               seed of the camera noise (default 1)\n"
    "  --drop-after N         for tests: after answering N actions, vents and\n"
    "                         captures (hello, ping, status, fault are not\n"
    "                         counted), close the connection on the next one,\n"
    "                         unanswered; once\n"
    "  --settle-timeout-s S   answer an action \"failed\" (state as before it) when its\n"
    "                         settle takes longer than S s, 1..3600 (default 30; the\n"
    "                         server's link waits 60 s for a reply)\n"
    "  --watchdog-ms MS       vent by itself after MS ms without a byte from the\n"
    "                         server while actuated, 100..5000 (default 2000)\n"
    "  --help                 this text\n"
    "Runs until SIGINT or SIGTERM.\n";

namespace {

double number(const std::string& flag, const std::string& text) {
  double v = 0.0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  if (text.empty() || ec != std::errc() || end != text.data() + text.size() || !std::isfinite(v))
    throw std::invalid_argument(flag + ": \"" + text + "\" is not a finite number");
  return v;
}

long long whole(const std::string& flag, const std::string& text, long long lo, long long hi) {
  long long v = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  if (text.empty() || ec != std::errc() || end != text.data() + text.size() || v < lo || v > hi)
    throw std::invalid_argument(flag + ": \"" + text + "\" is not a whole number in [" + std::to_string(lo) + ", " +
                                std::to_string(hi) + "]");
  return v;
}

std::vector<std::string> split_commas(const std::string& text) {
  std::vector<std::string> out;
  std::size_t start = 0;
  while (true) {
    const std::size_t end = text.find(',', start);
    out.push_back(text.substr(start, end - start));
    if (end == std::string::npos) return out;
    start = end + 1;
  }
}

SessionGrid parse_grid(const std::string& text) {
  const auto f = split_commas(text);
  if (f.size() != 6) throw std::invalid_argument("--grid: expected nx,ny,x0,y0,dx,dy, got \"" + text + "\"");
  SessionGrid g;
  g.nx = static_cast<int>(whole("--grid nx", f[0], 1, protocol::kMaxCaptureSamples));
  g.ny = static_cast<int>(whole("--grid ny", f[1], 1, protocol::kMaxCaptureSamples));
  g.x0_mm = number("--grid x0", f[2]);
  g.y0_mm = number("--grid y0", f[3]);
  g.dx_mm = number("--grid dx", f[4]);
  g.dy_mm = number("--grid dy", f[5]);
  if (g.dx_mm <= 0.0 || g.dy_mm <= 0.0) throw std::invalid_argument("--grid: dx and dy (mm) must be positive");
  if (static_cast<long>(g.nx) * g.ny > protocol::kMaxCaptureSamples)
    throw std::invalid_argument("--grid: " + std::to_string(g.nx) + " x " + std::to_string(g.ny) +
                                " samples exceeds " + std::to_string(protocol::kMaxCaptureSamples));
  return g;
}

void parse_listen(const std::string& text, EmulatorServerOptions& server) {
  const std::size_t colon = text.rfind(':');
  if (colon == std::string::npos || colon == 0)
    throw std::invalid_argument("--listen: expected HOST:PORT, got \"" + text + "\"");
  std::string host = text.substr(0, colon);
  if (host.size() >= 2 && host.front() == '[' && host.back() == ']') host = host.substr(1, host.size() - 2);
  server.host = host;
  server.port = static_cast<unsigned short>(whole("--listen port", text.substr(colon + 1), 0, 65535));
}

}  // namespace

EmulatorProgramOptions parse_emulator_options(const std::vector<std::string>& args) {
  EmulatorProgramOptions out;
  ArrayGeometry& geometry = out.config.geometry;
  geometry = {3, 4, 0.038, 4};
  std::optional<std::string> params_file, grid_text;
  std::optional<double> max_pressure_kpa, resolution_mm, dropout;
  std::vector<std::string> effects;
  CameraOptions& camera = out.config.camera;
  bool listen = false;

  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    const auto value = [&]() -> const std::string& {
      if (i + 1 >= args.size()) throw std::invalid_argument(a + " needs a value");
      return args[++i];
    };
    if (a == "--help" || a == "-h") out.help = true;
    else if (a == "--listen") parse_listen(value(), out.server), listen = true;
    else if (a == "--rows") geometry.rows = static_cast<int>(whole(a, value(), 1, 100));
    else if (a == "--cols") geometry.cols = static_cast<int>(whole(a, value(), 1, 100));
    else if (a == "--segments") geometry.segments = static_cast<int>(whole(a, value(), 2, 64));
    else if (a == "--cell-mm") {
      geometry.cell_size_m = number(a, value()) / 1000.0;
      if (!(geometry.cell_size_m > 0.0 && geometry.cell_size_m <= 1.0))
        throw std::invalid_argument("--cell-mm: must be within (0, 1000] mm");
    } else if (a == "--params") params_file = value();
    else if (a == "--effects") {
      for (const auto& name : split_commas(value())) {
        if (name.empty()) throw std::invalid_argument("--effects: empty effect name in the list");
        bool baseline = false;
        try {
          baseline = EffectRegistry::instance().get(name).baseline;
        } catch (const std::invalid_argument& e) {
          throw std::invalid_argument(std::string("--effects: ") + e.what());
        }
        if (baseline)
          throw std::invalid_argument("--effects: \"" + name + "\" is part of the baseline model, always on");
        effects.push_back(name);
      }
    } else if (a == "--max-pressure-kpa") {
      max_pressure_kpa = number(a, value());
      if (*max_pressure_kpa <= 0.0) throw std::invalid_argument("--max-pressure-kpa: must be > 0 kPa");
    } else if (a == "--grid") grid_text = value();
    else if (a == "--noise-mm" || a == "--camera-noise-mm") camera.noise_mm = number(a, value());
    else if (a == "--resolution-mm") resolution_mm = number(a, value());
    else if (a == "--dropout") dropout = number(a, value());
    else if (a == "--seed") camera.seed = static_cast<std::uint64_t>(whole(a, value(), 0, 1LL << 62));
    else if (a == "--drop-after") out.server.drop_after = whole(a, value(), 0, 1LL << 40);
    else if (a == "--settle-timeout-s")
      out.config.settle_timeout = std::chrono::seconds(whole(a, value(), 1, 3600));
    else if (a == "--watchdog-ms") out.server.watchdog = std::chrono::milliseconds(whole(a, value(), 100, 5000));
    else throw std::invalid_argument("unknown argument \"" + a + "\"");
  }
  if (out.help) return out;
  if (!listen) throw std::invalid_argument("missing --listen HOST:PORT");

  // Mesh validates the geometry; name the flags if it refuses.
  try {
    Mesh check(geometry);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(std::string("--rows/--cols/--segments/--cell-mm: ") + e.what());
  }
  SurfaceParameters& params = out.config.params;
  params = SurfaceParameters::paper_defaults(geometry);
  if (params_file) {
    try {
      const ModelParams model = read_model_params(*params_file, params);
      params = model.surface;
      model.apply_to(out.config.simulator);
    } catch (const std::exception& e) {
      throw std::invalid_argument(std::string("--params: ") + e.what());
    }
  }
  for (const auto& name : effects) out.config.simulator.extra_effects.push_back(name);
  if (max_pressure_kpa) params.max_pressure_pa = *max_pressure_kpa * 1000.0;

  camera.grid = grid_text ? parse_grid(*grid_text) : default_capture_grid(geometry);
  if (camera.noise_mm < 0.0) throw std::invalid_argument("--noise-mm: must be >= 0 mm");
  // The shared sessions' camera: noise comes rounded to 1 mm with 1 % gaps.
  camera.resolution_mm = resolution_mm.value_or(camera.noise_mm > 0.0 ? 1.0 : 0.0);
  camera.dropout = dropout.value_or(camera.noise_mm > 0.0 ? 0.01 : 0.0);
  if (camera.resolution_mm < 0.0) throw std::invalid_argument("--resolution-mm: must be >= 0 mm");
  if (!(camera.dropout >= 0.0 && camera.dropout < 1.0)) throw std::invalid_argument("--dropout: must be in [0, 1)");
  return out;
}

}  // namespace hj::device
