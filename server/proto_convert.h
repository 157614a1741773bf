// Translation between the public API's messages (proto/hapticjam/v1) and the
// library's types. No computation here: only copying, defaults and the
// checks that a message names something the library can take.
#pragma once

#include <string>

#include "device/device_link.h"
#include "hapticjam/v1/array.pb.h"
#include "hapticjam/v1/goal.pb.h"
#include "hapticjam/v1/plan.pb.h"
#include "hapticjam/v1/surface.pb.h"
#include "server_limits.h"
#include "model/action.h"
#include "model/device_state.h"
#include "shapes/goal_importer.h"
#include "shapes/resample.h"
#include "sim/simulator.h"

namespace hj::server {

namespace v1 = ::hapticjam::v1;

// An ArraySpec as the library's geometry, parameters (paper defaults for the
// array, then the fields set) and simulator options (the effects).
struct ArrayConfig {
  ArrayGeometry geometry;
  SurfaceParameters params;
  SimulatorOptions simulator;
};

// @throws std::invalid_argument naming the field and the limit: rows or cols
//         missing or over max_array_side_cells, segments over max_segments,
//         more than max_mesh_points points, a bad parameter or effect.
ArrayConfig array_from_proto(const v1::ArraySpec& spec, const ServerLimits& limits);

// Import options of a goal (hue, up axis, view resolution) within the limits.
// @throws std::invalid_argument naming the field.
ImportOptions import_options_from_proto(const v1::GoalOptions& options, const ServerLimits& limits);
double max_height_from_proto(const v1::GoalOptions& options);
// Scaled or absolute heights; absolute needs a CSV or TIFF goal file (or a
// map) and no max_height_mm. @throws std::invalid_argument naming the field.
GoalHeights heights_from_proto(const v1::Goal& goal);

// A device step: one of the five actions or a capture.
struct DeviceStep {
  bool capture = false;
  Action action;  // when !capture
  std::string label;
};

// @throws std::invalid_argument naming `where` ("step 3") when no op is set.
DeviceStep step_from_proto(const v1::Step& step, const std::string& where);
void action_to_proto(const Action& action, v1::Step* out);

// Heights (mm) per mesh point and the state that holds them.
void snapshot_to_proto(const Mesh& mesh, const DeviceState& state, int steps_applied, v1::SurfaceSnapshot* out);
void capture_to_proto(const device::Capture& capture, v1::CaptureFrame* out);

}  // namespace hj::server
