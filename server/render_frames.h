// The render loop's captures and surfaces between the wire and the library:
// a device frame as heights, its grid for the comparison (metrics/height_error.h)
// and the rasteriser (calib/rasterize.h), and the errors, heights and camera
// plane written back into the render's messages.
#pragma once

#include <Eigen/Core>
#include <string>

#include "calib/session.h"
#include "hapticjam/v1/render_service.pb.h"
#include "metrics/height_error.h"
#include "model/mesh.h"

namespace hj::server {

// Row-major heights into a repeated field.
void add_heights(const Eigen::MatrixXd& m, google::protobuf::RepeatedField<double>* out);
void error_to_proto(const HeightError& e, hapticjam::v1::SurfaceError* out);
void camera_to_proto(const CameraPlane& plane, const std::string& source, hapticjam::v1::CameraPlane* out);

FrameGrid frame_grid(const hapticjam::v1::CaptureGrid& g);
SessionGrid session_grid(const hapticjam::v1::CaptureGrid& g);
// A capture's heights (ny x nx). @throws ServiceError INTERNAL for a frame
// whose samples do not fill its grid.
Eigen::MatrixXd frame_heights(const hapticjam::v1::CaptureFrame& frame);
// The predicted surface as the camera would see it at the rest points: like with like.
Eigen::MatrixXd predicted_at_rest_points(const Mesh& mesh, const Eigen::Matrix3Xd& x,
                                         const hapticjam::v1::CaptureGrid& g);

}  // namespace hj::server
