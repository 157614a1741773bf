// Render tests' support: a device-makeable goal, made by the emulator's own
// model from a known sequence (sent on a raw line, read back with `truth`,
// then vented), written as a CSV of absolute heights at the planner's mesh
// points; and the true surface's error against a goal.
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <string>
#include <vector>

#include "calib/frame_csv.h"
#include "device/protocol.h"
#include "e2e_support.h"
#include "metrics/height_error.h"
#include "model/mesh.h"

namespace hj::testing_support {

// The emulator's true surface at the rest points of `mesh`, mm.
inline Eigen::MatrixXd true_surface(EmulatorLine& line, const Mesh& mesh) {
  const std::string reply = line.request("truth");
  const std::string prefix = "ok ";
  if (reply.rfind(prefix, 0) != 0) throw std::runtime_error("truth refused: " + reply);
  const std::string payload = reply.substr(reply.find(' ', prefix.size()) + 1);
  const device::Capture c = device::protocol::parse_capture(payload);
  return frame_at_rest_points(mesh, c.heights_mm, {c.grid.nx, c.grid.ny, c.grid.x0_mm, c.grid.y0_mm, c.grid.dx_mm, c.grid.dy_mm});
}

// Runs `commands` ("set_pressure 1500", "jam 0 1" ...) on the emulator, writes
// its true surface at `mesh`'s points to `file` (row 0 = the top, as a goal
// image), vents, and returns the surface.
inline Eigen::MatrixXd make_goal(int port, const Mesh& mesh, const std::vector<std::string>& commands,
                                 const std::filesystem::path& file) {
  EmulatorLine line(port);
  for (const auto& c : commands) {
    const std::string reply = line.request(c);
    if (reply.rfind("ok", 0) != 0) throw std::runtime_error(c + ": " + reply);
  }
  const Eigen::MatrixXd goal = true_surface(line, mesh);
  write_frame_csv(file, goal.colwise().reverse());
  line.request("vent");
  return goal;
}

}  // namespace hj::testing_support
