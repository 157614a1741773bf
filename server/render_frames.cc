#include "render_frames.h"

#include "calib/rasterize.h"
#include "service_error.h"

namespace hj::server {

namespace v1 = ::hapticjam::v1;
using grpc::StatusCode;

void add_heights(const Eigen::MatrixXd& m, google::protobuf::RepeatedField<double>* out) {
  out->Reserve(int(m.size()));
  for (int i = 0; i < m.rows(); ++i)
    for (int j = 0; j < m.cols(); ++j) out->Add(m(i, j));
}

void error_to_proto(const HeightError& e, v1::SurfaceError* out) {
  out->set_mae_mm(e.mae_mm);
  out->set_rmse_mm(e.rmse_mm);
  if (e.correlation.value) out->set_correlation(*e.correlation.value);
  out->set_points(e.points);
}

FrameGrid frame_grid(const v1::CaptureGrid& g) { return {g.nx(), g.ny(), g.x0_mm(), g.y0_mm(), g.dx_mm(), g.dy_mm()}; }

Eigen::MatrixXd frame_heights(const v1::CaptureFrame& frame) {
  const int nx = frame.grid().nx(), ny = frame.grid().ny();
  if (nx < 1 || ny < 1 || frame.heights_mm_size() != nx * ny)
    throw ServiceError(StatusCode::INTERNAL, "the device returned a capture of " +
                                                 std::to_string(frame.heights_mm_size()) + " samples for a grid of " +
                                                 std::to_string(nx) + " x " + std::to_string(ny));
  Eigen::MatrixXd out(ny, nx);
  for (int iy = 0; iy < ny; ++iy)
    for (int ix = 0; ix < nx; ++ix) out(iy, ix) = frame.heights_mm(iy * nx + ix);
  return out;
}

SessionGrid session_grid(const v1::CaptureGrid& g) {
  SessionGrid grid;
  grid.nx = g.nx(), grid.ny = g.ny(), grid.x0_mm = g.x0_mm(), grid.y0_mm = g.y0_mm();
  grid.dx_mm = g.dx_mm(), grid.dy_mm = g.dy_mm();
  return grid;
}

Eigen::MatrixXd predicted_at_rest_points(const Mesh& mesh, const Eigen::Matrix3Xd& x, const v1::CaptureGrid& g) {
  return frame_at_rest_points(mesh, rasterize_top_view(mesh, x, session_grid(g)), frame_grid(g));
}

void camera_to_proto(const CameraPlane& plane, const std::string& source, v1::CameraPlane* out) {
  out->set_tilt_x_mrad(plane.tilt_x_mrad), out->set_tilt_y_mrad(plane.tilt_y_mrad);
  out->set_offset_mm(plane.offset_mm), out->set_points(plane.points);
  out->set_source(source);
}

}  // namespace hj::server
