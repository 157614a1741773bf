// Conversions between the API's messages (proto/hapticjam/v1) and the files
// the command line reads and writes: plan.json steps (the session-format
// vocabulary, docs/session-format.md) to a Plan, surface snapshots and
// capture frames to matrices, and messages to one-line JSON.
#pragma once

#include <Eigen/Core>
#include <google/protobuf/message.h>
#include <nlohmann/json.hpp>
#include <string>

#include "hapticjam/v1/plan.pb.h"
#include "hapticjam/v1/surface.pb.h"

namespace hj::cli {

// The "steps" of a plan.json (what `hapticjam plan` and `remote plan` write),
// of a session.json, or a bare list of steps, as a Plan. Only the shape is
// checked here (ops, keys, numbers); ranges are the device's business.
// @throws std::invalid_argument naming `source`, the step and the key.
hapticjam::v1::Plan plan_from_steps_json(const nlohmann::json& doc, const std::string& source);

// (point_rows x point_cols) heights in mm, row i along +y.
// @throws std::runtime_error if the sizes disagree.
Eigen::MatrixXd snapshot_heights(const hapticjam::v1::SurfaceSnapshot& snapshot);
// The goal heights a plan or preview result carries (row-major, mm) as a
// (rows x cols) matrix. @throws std::runtime_error if their count differs.
Eigen::MatrixXd goal_heights(const google::protobuf::RepeatedField<double>& heights_mm, Eigen::Index rows,
                             Eigen::Index cols);
// The in-plane positions (mm) of the snapshot's points, same shape as its
// heights; false if the server sent none.
bool snapshot_positions(const hapticjam::v1::SurfaceSnapshot& snapshot, Eigen::MatrixXd& x_mm, Eigen::MatrixXd& y_mm);
// (ny x nx) heights in mm, NaN where the camera saw nothing.
Eigen::MatrixXd frame_heights(const hapticjam::v1::CaptureFrame& frame);

// A captured frame against a predicted surface at the mesh points it covers
// (bilinear from the frame's four samples around each point; points with a
// missing sample around them are skipped). Each point is looked up where it
// sits: at (x_mm, y_mm) when given (the predicted in-plane positions), else
// at its rest position (j s, i s), which is wrong by the in-plane pull of a
// domed membrane.
struct SurfaceDifference {
  int points = 0;        // mesh points compared
  double rms_mm = 0.0;   // root mean square of captured - predicted
  double max_abs_mm = 0.0;
  double mean_mm = 0.0;  // mean of captured - predicted
};
SurfaceDifference compare_capture(const hapticjam::v1::CaptureFrame& frame, const Eigen::MatrixXd& predicted_mm,
                                  double point_spacing_mm, const Eigen::MatrixXd* x_mm = nullptr,
                                  const Eigen::MatrixXd* y_mm = nullptr);

// One line of JSON with the proto field names, defaults included.
std::string to_json_line(const google::protobuf::Message& message);

}  // namespace hj::cli
