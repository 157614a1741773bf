// A measurement session read from its session.json ("hapticjam.session/1",
// docs/session-format.md): the device, the camera's sample grid, and the
// steps (actions and captures) in order. Frames are read by frame_csv.h.
#pragma once

#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "model/action.h"
#include "model/mesh.h"

namespace hj {

// A session file or frame that cannot be used; the message names the file,
// and where it applies the step index and the key.
class SessionError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Where a frame samples the surface: sample (ix, iy) is at
// (x0 + ix dx, y0 + iy dy) mm. A frame is (ny x nx), row iy, column ix.
struct SessionGrid {
  int nx = 0;
  int ny = 0;
  double x0_mm = 0.0;
  double y0_mm = 0.0;
  double dx_mm = 0.0;
  double dy_mm = 0.0;

  double x_mm(int ix) const { return x0_mm + ix * dx_mm; }
  double y_mm(int iy) const { return y0_mm + iy * dy_mm; }
};

struct SessionDevice {
  int rows = 0;
  int cols = 0;
  double cell_size_mm = 0.0;
  double max_pressure_kpa = 0.0;

  // The mesh geometry of this device at p segments per cell edge.
  ArrayGeometry geometry(int segments = 4) const { return {rows, cols, cell_size_mm / 1000.0, segments}; }
};

struct SessionStep {
  enum class Kind { kAction, kCapture };
  Kind kind = Kind::kAction;
  Action action;      // kAction; pressures in Pa
  std::string frame;  // kCapture: path relative to the session folder
  std::string label;  // kCapture: optional, empty if absent
  int index = 0;      // position in "steps"
};

struct Session {
  std::filesystem::path dir;  // folder holding session.json
  std::string name;           // "name", or the folder's name if absent
  SessionDevice device;
  double sensor_accuracy_mm = 3.0;
  double sensor_resolution_mm = 1.0;
  SessionGrid grid;
  std::vector<SessionStep> steps;

  std::filesystem::path frame_path(const SessionStep& step) const { return dir / step.frame; }
};

// Reads and validates a session; `path` is its session.json or the folder
// holding it. Frames are not opened.
// @throws SessionError naming the file, step and key that is wrong.
Session read_session(const std::filesystem::path& path);

}  // namespace hj
