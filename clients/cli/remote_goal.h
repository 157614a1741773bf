// The goal and array flags `remote plan` and `remote preview` share (the same
// as local `hapticjam plan`), turned into the API's Goal and ArraySpec.
#pragma once

#include <string>

#include "args.h"
#include "hapticjam/v1/array.pb.h"
#include "hapticjam/v1/goal.pb.h"

namespace hj::cli {

constexpr const char* kRemoteGoalUsage =
    "  GOAL                  a goal file sent as bytes (CSV, PNG, TIFF, STL, OBJ, PLY, glTF/GLB, 3MF)\n"
    "  --map NAME            or a map the server was started with (--map NAME=FILE)\n"
    "  --rows R, --cols C    array size in cells\n"
    "  --segments P          segments per cell edge (default: the server's)\n"
    "  --cell-mm MM          cell side (default 38)\n"
    "  --planner NAME        default: the server's (portfolio; preview: algorithm2)\n"
    "  --max-height-mm H     goal height range on the display (default: 10 mm per cell\n"
    "                        of the array's shorter side, e.g. 30 mm at 3 x 4)\n"
    "  --heights absolute    a CSV or float TIFF goal at face value: mm above the clamped\n"
    "                        edge's plane; (R p + 1) x (C p + 1) values = the mesh points\n"
    "  --region x0,y0,x1,y1  zoom: pixels, or fractions of the image if all <= 1\n"
    "  --hue                 colour topographic map: red-orange high, blue-purple low\n"
    "  --no-sidecar          do not send NAME.json beside the goal (it turns DEMs north-up)\n"
    "  --up-axis A           a mesh's up axis: x, y, z (default), -x, -y or -z\n"
    "  --view-resolution N   pixels of a mesh's top view along its longer side (default 256)\n";

struct GoalArgs {
  std::string file, map_name, region, planner, up_axis;
  int rows = 0, cols = 0, segments = 0, view_resolution = 0;
  double cell_mm = 0.0, max_height_mm = 0.0;
  bool hue = false;
  bool absolute_heights = false;  // --heights absolute
  bool use_sidecar = true;  // send NAME.json beside the goal (--no-sidecar: do not)

  // Consumes one goal or array flag, or the GOAL argument; false if the
  // argument is not one of them. @throws std::invalid_argument on a bad value.
  bool take(ArgCursor& cursor);
  // @throws std::invalid_argument: no goal or both, no --rows/--cols.
  void validate() const;

  hapticjam::v1::ArraySpec array() const;
  // Reads the goal file. @throws std::runtime_error naming it if it cannot.
  hapticjam::v1::Goal goal() const;
  // "volcano.csv" or "map volcano": for messages.
  std::string label() const;
};

}  // namespace hj::cli
