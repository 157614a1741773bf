#include "metrics/height_error.h"

#include "metrics/same_shape.h"

#include <algorithm>
#include <Eigen/Dense>
#include <cmath>
#include <stdexcept>
#include <string>

namespace hj {
namespace {

// The frame at (x, y) mm, bilinear over the valid samples of the cell around it.
double interpolate(const Eigen::MatrixXd& frame, const FrameGrid& g, double x_mm, double y_mm) {
  const double u = (x_mm - g.x0_mm) / g.dx_mm, v = (y_mm - g.y0_mm) / g.dy_mm;
  constexpr double kSlack = 1e-9;  // a point on the grid's last line is on the grid
  if (u < -kSlack || v < -kSlack || u > g.nx - 1 + kSlack || v > g.ny - 1 + kSlack) return std::nan("");
  const int ix = std::clamp(int(std::floor(u)), 0, std::max(0, g.nx - 2));
  const int iy = std::clamp(int(std::floor(v)), 0, std::max(0, g.ny - 2));
  const double fx = std::clamp(u - ix, 0.0, 1.0), fy = std::clamp(v - iy, 0.0, 1.0);
  double sum = 0.0, weight = 0.0;
  for (int dy = 0; dy <= 1; ++dy)
    for (int dx = 0; dx <= 1; ++dx) {
      const int sx = std::min(ix + dx, g.nx - 1), sy = std::min(iy + dy, g.ny - 1);
      const double w = (dx ? fx : 1.0 - fx) * (dy ? fy : 1.0 - fy);
      const double h = frame(sy, sx);
      if (std::isnan(h) || w <= 0.0) continue;
      sum += w * h;
      weight += w;
    }
  return weight > 0.0 ? sum / weight : std::nan("");
}

}  // namespace

Eigen::MatrixXd frame_at_rest_points(const Mesh& mesh, const Eigen::MatrixXd& frame_mm, const FrameGrid& grid) {
  if (frame_mm.rows() != grid.ny || frame_mm.cols() != grid.nx)
    throw std::invalid_argument("frame of " + shape_text(frame_mm) + " samples for a grid of ny x nx = " +
                                std::to_string(grid.ny) + " x " + std::to_string(grid.nx));
  if (!(grid.dx_mm > 0.0) || !(grid.dy_mm > 0.0)) throw std::invalid_argument("frame grid spacing must be positive");
  const double h_mm = mesh.spacing() * 1000.0;
  Eigen::MatrixXd out(mesh.point_rows(), mesh.point_cols());
  for (int i = 0; i < out.rows(); ++i)
    for (int j = 0; j < out.cols(); ++j) out(i, j) = interpolate(frame_mm, grid, j * h_mm, i * h_mm);
  return out;
}

HeightError height_error(const Eigen::MatrixXd& reference_mm, const Eigen::MatrixXd& measured_mm) {
  check_same_shape(reference_mm, measured_mm, "height_error");
  HeightError out;
  double abs_sum = 0.0, square_sum = 0.0;
  for (Eigen::Index k = 0; k < reference_mm.size(); ++k) {
    const double d = measured_mm.data()[k] - reference_mm.data()[k];
    if (!std::isfinite(d)) continue;
    abs_sum += std::abs(d);
    square_sum += d * d;
    ++out.points;
  }
  if (out.points == 0) throw std::invalid_argument("height_error: no point is finite in both surfaces");
  out.mae_mm = abs_sum / out.points;
  out.rmse_mm = std::sqrt(square_sum / out.points);
  out.correlation = correlate(reference_mm, measured_mm);
  return out;
}

namespace {

// The plane's height at point (i, j) of the mesh, mm.
double plane_at(const Mesh& mesh, const CameraPlane& plane, int i, int j) {
  const double h_mm = mesh.spacing() * 1000.0;
  const double xc = 0.5 * (mesh.point_cols() - 1) * h_mm, yc = 0.5 * (mesh.point_rows() - 1) * h_mm;
  return plane.offset_mm + 1e-3 * (plane.tilt_x_mrad * (j * h_mm - xc) + plane.tilt_y_mrad * (i * h_mm - yc));
}

}  // namespace

CameraPlane fit_camera_plane(const Mesh& mesh, const Eigen::MatrixXd& measured_mm) {
  const int n_i = mesh.point_rows(), n_j = mesh.point_cols();
  if (measured_mm.rows() != n_i || measured_mm.cols() != n_j)
    throw std::invalid_argument("fit_camera_plane: " + shape_text(measured_mm) + " heights for a mesh of " +
                                std::to_string(n_i) + " x " + std::to_string(n_j) + " points");
  const double h_mm = mesh.spacing() * 1000.0;
  const double xc = 0.5 * (n_j - 1) * h_mm, yc = 0.5 * (n_i - 1) * h_mm;
  Eigen::Matrix3d normal = Eigen::Matrix3d::Zero();
  Eigen::Vector3d rhs = Eigen::Vector3d::Zero();
  CameraPlane plane;
  for (int i = 0; i < n_i; ++i)
    for (int j = 0; j < n_j; ++j) {
      const bool edge = i == 0 || j == 0 || i == n_i - 1 || j == n_j - 1;
      if (!edge || !std::isfinite(measured_mm(i, j))) continue;
      const Eigen::Vector3d row(1.0, 1e-3 * (j * h_mm - xc), 1e-3 * (i * h_mm - yc));
      normal += row * row.transpose();
      rhs += row * measured_mm(i, j);
      ++plane.points;
    }
  if (plane.points < 3)
    throw std::invalid_argument("fit_camera_plane: " + std::to_string(plane.points) +
                                " edge points seen, a plane needs 3");
  const Eigen::Vector3d p = normal.ldlt().solve(rhs);
  plane.offset_mm = p(0), plane.tilt_x_mrad = p(1), plane.tilt_y_mrad = p(2);
  return plane;
}

Eigen::MatrixXd without_camera_plane(const Mesh& mesh, const Eigen::MatrixXd& measured_mm, const CameraPlane& plane) {
  Eigen::MatrixXd out = measured_mm;
  for (int i = 0; i < out.rows(); ++i)
    for (int j = 0; j < out.cols(); ++j) out(i, j) -= plane_at(mesh, plane, i, j);
  return out;
}

Eigen::MatrixXd learned_targets(const Eigen::MatrixXd& targets_mm, const Eigen::MatrixXd& goal_mm,
                                const Eigen::MatrixXd& measured_mm, double gain) {
  check_same_shape(targets_mm, goal_mm, "learned_targets (targets, goal)");
  check_same_shape(goal_mm, measured_mm, "learned_targets (goal, measured)");
  Eigen::MatrixXd out = targets_mm;
  for (Eigen::Index k = 0; k < out.size(); ++k) {
    const double error = goal_mm.data()[k] - measured_mm.data()[k];
    if (std::isfinite(error)) out.data()[k] += gain * error;
  }
  return out;
}

}  // namespace hj
