#include "calib/session.h"

#include <climits>
#include <cmath>
#include <fstream>
#include <iterator>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string_view>
#include <utility>

#include "model/parameters.h"

namespace hj {

namespace {

using json = nlohmann::json;

constexpr std::string_view kFormat = "hapticjam.session/1";
constexpr long long kMaxGridSamples = 25'000'000;
// Steps of one session, checked before any is read (the array's size is
// bounded by the mesh's own point limit).
constexpr std::size_t kMaxSessionSteps = 100'000;

// Where a message points: the file, and the step being read (if any).
struct Context {
  std::string file;
  std::string step;  // e.g. `steps[3] ("jam")`; empty outside "steps"
};

// A short rendering of a JSON value for messages.
std::string shown(const json& value) {
  std::string text = value.dump();
  if (text.size() > 60) text = text.substr(0, 57) + "...";
  return text;
}

[[noreturn]] void fail(const Context& ctx, std::string_view key, const std::string& what) {
  std::string message = ctx.file + ": ";
  if (!ctx.step.empty()) message += ctx.step + ": ";
  message += "key \"" + std::string(key) + "\": " + what;
  throw SessionError(message);
}

const json& require(const json& object, const char* key, const Context& ctx, std::string_view key_path) {
  const auto it = object.find(key);
  if (it == object.end()) fail(ctx, key_path, "missing (required)");
  return *it;
}

const json& require_object(const json& parent, const char* key, const Context& ctx) {
  const json& value = require(parent, key, ctx, key);
  if (!value.is_object()) fail(ctx, key, "must be an object, got " + shown(value));
  return value;
}

int as_int(const json& value, const Context& ctx, std::string_view key_path) {
  if (!value.is_number_integer()) fail(ctx, key_path, "must be an integer, got " + shown(value));
  if (value.is_number_unsigned()) {
    if (value.get<unsigned long long>() > static_cast<unsigned long long>(INT_MAX))
      fail(ctx, key_path, "integer " + shown(value) + " is too large");
    return static_cast<int>(value.get<unsigned long long>());
  }
  const long long v = value.get<long long>();
  if (v < INT_MIN || v > INT_MAX) fail(ctx, key_path, "integer " + shown(value) + " is out of range");
  return static_cast<int>(v);
}

double as_number(const json& value, const Context& ctx, std::string_view key_path) {
  if (!value.is_number()) fail(ctx, key_path, "must be a number, got " + shown(value));
  const double v = value.get<double>();
  if (!std::isfinite(v)) fail(ctx, key_path, "must be a finite number, got " + shown(value));
  return v;
}

int positive_int(const json& object, const char* key, const Context& ctx, std::string_view key_path) {
  const int v = as_int(require(object, key, ctx, key_path), ctx, key_path);
  if (v <= 0) fail(ctx, key_path, "must be positive, got " + std::to_string(v));
  return v;
}

double positive_number(const json& value, const Context& ctx, std::string_view key_path, const char* unit) {
  const double v = as_number(value, ctx, key_path);
  if (v <= 0.0) fail(ctx, key_path, std::string("must be a positive length in ") + unit + ", got " + shown(value));
  return v;
}

std::string as_string(const json& value, const Context& ctx, std::string_view key_path) {
  if (!value.is_string()) fail(ctx, key_path, "must be a string, got " + shown(value));
  return value.get<std::string>();
}

SessionDevice read_device(const json& root, const Context& ctx) {
  const json& d = require_object(root, "device", ctx);
  SessionDevice device;
  device.rows = positive_int(d, "rows", ctx, "device.rows");
  device.cols = positive_int(d, "cols", ctx, "device.cols");
  device.cell_size_mm = positive_number(require(d, "cell_size_mm", ctx, "device.cell_size_mm"), ctx,
                                        "device.cell_size_mm", "mm");
  const json& max_kpa = require(d, "max_pressure_kpa", ctx, "device.max_pressure_kpa");
  device.max_pressure_kpa = as_number(max_kpa, ctx, "device.max_pressure_kpa");
  if (device.max_pressure_kpa <= 0.0)
    fail(ctx, "device.max_pressure_kpa", "must be a positive pressure in kPa, got " + shown(max_kpa));
  return device;
}

void read_sensor(const json& root, const Context& ctx, Session& session) {
  const auto it = root.find("sensor");
  if (it == root.end()) return;
  if (!it->is_object()) fail(ctx, "sensor", "must be an object, got " + shown(*it));
  if (const auto a = it->find("accuracy_mm"); a != it->end())
    session.sensor_accuracy_mm = positive_number(*a, ctx, "sensor.accuracy_mm", "mm");
  if (const auto r = it->find("resolution_mm"); r != it->end())
    session.sensor_resolution_mm = positive_number(*r, ctx, "sensor.resolution_mm", "mm");
}

SessionGrid read_grid(const json& root, const Context& ctx) {
  const json& g = require_object(root, "grid", ctx);
  SessionGrid grid;
  grid.nx = positive_int(g, "nx", ctx, "grid.nx");
  grid.ny = positive_int(g, "ny", ctx, "grid.ny");
  const long long samples = static_cast<long long>(grid.nx) * grid.ny;
  if (samples > kMaxGridSamples)
    fail(ctx, "grid.nx", "grid of " + std::to_string(grid.nx) + " x " + std::to_string(grid.ny) + " = " +
                             std::to_string(samples) + " samples is over the limit of " +
                             std::to_string(kMaxGridSamples));
  grid.x0_mm = as_number(require(g, "x0_mm", ctx, "grid.x0_mm"), ctx, "grid.x0_mm");
  grid.y0_mm = as_number(require(g, "y0_mm", ctx, "grid.y0_mm"), ctx, "grid.y0_mm");
  grid.dx_mm = positive_number(require(g, "dx_mm", ctx, "grid.dx_mm"), ctx, "grid.dx_mm", "mm");
  grid.dy_mm = positive_number(require(g, "dy_mm", ctx, "grid.dy_mm"), ctx, "grid.dy_mm", "mm");
  return grid;
}

// A cell [row, col] or node [a, b]: a 2-element integer array.
std::pair<int, int> index_pair(const json& step, const char* key, const Context& ctx) {
  const json& v = require(step, key, ctx, key);
  const bool ok = v.is_array() && v.size() == 2 && v[0].is_number_integer() && v[1].is_number_integer();
  if (!ok) {
    const char* form = std::string_view(key) == "cell" ? "[row, col]" : "[a, b]";
    fail(ctx, key, std::string("must be a 2-element integer array ") + form + ", got " + shown(v));
  }
  return {as_int(v[0], ctx, key), as_int(v[1], ctx, key)};
}

// A frame path must name a file inside the session folder.
std::string frame_of(const json& step, const Context& ctx) {
  const std::string frame = as_string(require(step, "frame", ctx, "frame"), ctx, "frame");
  const std::filesystem::path p(frame);
  if (frame.empty() || !p.has_filename()) fail(ctx, "frame", "must name a file, got " + shown(step["frame"]));
  if (p.has_root_path())
    fail(ctx, "frame", "must be relative to the session folder, got " + shown(step["frame"]));
  for (const auto& part : p)
    if (part == "..") fail(ctx, "frame", "must stay inside the session folder (no \"..\"), got " + shown(step["frame"]));
  return frame;
}

// Checks an action against the device, naming `key` (Action's message
// starts with the key word, which the prefix already gives).
void validate_action(const Action& action, const Mesh& mesh, const SurfaceParameters& params, const char* key,
                     const Context& ctx) {
  try {
    action.validate(mesh, params);
  } catch (const std::invalid_argument& e) {
    std::string what = e.what();
    const std::string prefix = std::string(key) + " ";
    if (what.rfind(prefix, 0) == 0) what.erase(0, prefix.size());
    fail(ctx, key, what);
  }
}

SessionStep read_step(const json& step, int index, const Mesh& mesh, const SurfaceParameters& params,
                      Context ctx) {
  ctx.step = "steps[" + std::to_string(index) + "]";
  if (!step.is_object()) fail(ctx, "op", "the step must be an object, got " + shown(step));
  const std::string op = as_string(require(step, "op", ctx, "op"), ctx, "op");
  ctx.step += " (" + json(op).dump() + ")";

  SessionStep out;
  out.index = index;
  if (op == "capture") {
    out.kind = SessionStep::Kind::kCapture;
    out.frame = frame_of(step, ctx);
    if (const auto label = step.find("label"); label != step.end()) out.label = as_string(*label, ctx, "label");
    return out;
  }

  out.kind = SessionStep::Kind::kAction;
  const char* key = nullptr;
  if (op == "set_pressure") {
    key = "kpa";
    out.action = Action::set_pressure(as_number(require(step, key, ctx, key), ctx, key) * 1000.0);
  } else if (op == "jam" || op == "unjam") {
    key = "cell";
    const auto [r, c] = index_pair(step, key, ctx);
    out.action = op == "jam" ? Action::jam(r, c) : Action::unjam(r, c);
  } else if (op == "pin" || op == "unpin") {
    key = "node";
    const auto [a, b] = index_pair(step, key, ctx);
    out.action = op == "pin" ? Action::pin(a, b) : Action::unpin(a, b);
  } else {
    fail(ctx, "op", "unknown op " + json(op).dump() + "; expected capture, set_pressure, jam, unjam, pin or unpin");
  }
  validate_action(out.action, mesh, params, key, ctx);
  return out;
}

std::vector<SessionStep> read_steps(const json& root, const SessionDevice& device, const Context& ctx) {
  const json& steps = require(root, "steps", ctx, "steps");
  if (!steps.is_array()) fail(ctx, "steps", "must be an array, got " + shown(steps));
  if (steps.size() > kMaxSessionSteps)
    fail(ctx, "steps", std::to_string(steps.size()) + " steps is over the limit of " + std::to_string(kMaxSessionSteps));

  // The device's mesh, only to check cells and nodes (at the model's p = 4).
  std::optional<Mesh> mesh;
  try {
    mesh.emplace(device.geometry(4));
  } catch (const std::invalid_argument& e) {
    fail(ctx, "device", e.what());
  }
  SurfaceParameters params;
  params.max_pressure_pa = device.max_pressure_kpa * 1000.0;

  std::vector<SessionStep> out;
  std::map<std::string, int> frame_owner;  // normalised frame path -> step
  out.reserve(steps.size());
  for (std::size_t i = 0; i < steps.size(); ++i) {
    out.push_back(read_step(steps[i], static_cast<int>(i), *mesh, params, ctx));
    const SessionStep& step = out.back();
    if (step.kind != SessionStep::Kind::kCapture) continue;
    const std::string normal = std::filesystem::path(step.frame).lexically_normal().string();
    const auto [it, inserted] = frame_owner.emplace(normal, step.index);
    if (!inserted) {
      Context step_ctx = ctx;
      step_ctx.step = "steps[" + std::to_string(i) + "] (\"capture\")";
      fail(step_ctx, "frame", json(step.frame).dump() + " is already the frame of steps[" +
                                  std::to_string(it->second) + "]");
    }
  }
  return out;
}

json parse_file(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) {
    std::error_code ec;
    const bool exists = std::filesystem::exists(file, ec);
    throw SessionError(file.string() + ": cannot open session file (" + (exists ? "not readable" : "no such file") +
                       ")");
  }
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw SessionError(file.string() + ": read error");
  try {
    return json::parse(text);
  } catch (const json::parse_error& e) {
    // Drop nlohmann's "[json.exception.parse_error.101] " tag.
    std::string what = e.what();
    if (const auto end = what.find("] "); what.rfind("[json.exception", 0) == 0 && end != std::string::npos)
      what.erase(0, end + 2);
    throw SessionError(file.string() + ": invalid JSON at byte " + std::to_string(e.byte) + ": " + what);
  }
}

}  // namespace

Session read_session(const std::filesystem::path& path) {
  std::error_code ec;
  const std::filesystem::path file = std::filesystem::is_directory(path, ec) ? path / "session.json" : path;
  const json root = parse_file(file);
  const Context ctx{file.string(), ""};
  if (!root.is_object()) throw SessionError(ctx.file + ": the top level must be a JSON object, got " + shown(root));

  const json& format = require(root, "format", ctx, "format");
  if (!format.is_string() || format.get<std::string>() != kFormat)
    fail(ctx, "format", "must be \"" + std::string(kFormat) + "\", got " + shown(format));

  Session session;
  session.dir = file.has_parent_path() ? file.parent_path() : std::filesystem::path(".");
  if (const auto name = root.find("name"); name != root.end())
    session.name = as_string(*name, ctx, "name");
  else
    session.name = std::filesystem::absolute(file, ec).lexically_normal().parent_path().filename().string();
  session.device = read_device(root, ctx);
  read_sensor(root, ctx, session);
  session.grid = read_grid(root, ctx);
  session.steps = read_steps(root, session.device, ctx);
  return session;
}

}  // namespace hj
