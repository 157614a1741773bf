#include "calib/rasterize.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace hj {

namespace {

// A sample on an edge or vertex is inside up to this fraction of the
// triangle's own size, so rounding never opens a gap between triangles.
constexpr double kEdgeTolerance = 1e-12;

// One triangle's xy range as grid indices, [lo, hi] (empty if lo > hi).
struct IndexRange {
  int lo = 0;
  int hi = -1;
};

IndexRange samples_within(double min_mm, double max_mm, double origin_mm, double step_mm, int count) {
  const double lo = std::ceil((min_mm - origin_mm) / step_mm);
  const double hi = std::floor((max_mm - origin_mm) / step_mm);
  if (!(lo <= count - 1) || !(hi >= 0)) return {};
  return {static_cast<int>(std::max(lo, 0.0)), static_cast<int>(std::min(hi, count - 1.0))};
}

// Draws triangle (a, b, c), vertices in mm, into heights_mm keeping the max.
void draw_triangle(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                   const SessionGrid& grid, Eigen::MatrixXd& heights_mm) {
  if (!a.allFinite() || !b.allFinite() || !c.allFinite()) return;

  // Edge vectors from a; twice the signed xy area.
  const double ux = b.x() - a.x(), uy = b.y() - a.y();
  const double vx = c.x() - a.x(), vy = c.y() - a.y();
  const double area2 = ux * vy - vx * uy;
  if (area2 == 0.0) return;

  // Candidate samples: the xy bounding box, widened by the edge tolerance.
  const double min_x = std::min({a.x(), b.x(), c.x()}), max_x = std::max({a.x(), b.x(), c.x()});
  const double min_y = std::min({a.y(), b.y(), c.y()}), max_y = std::max({a.y(), b.y(), c.y()});
  const double slack = 1e-9 * std::max(max_x - min_x, max_y - min_y);
  const IndexRange rx = samples_within(min_x - slack, max_x + slack, grid.x0_mm, grid.dx_mm, grid.nx);
  const IndexRange ry = samples_within(min_y - slack, max_y + slack, grid.y0_mm, grid.dy_mm, grid.ny);

  const double inv_area2 = 1.0 / area2;
  for (int iy = ry.lo; iy <= ry.hi; ++iy) {
    const double py = grid.y_mm(iy) - a.y();
    for (int ix = rx.lo; ix <= rx.hi; ++ix) {
      const double px = grid.x_mm(ix) - a.x();
      // Barycentric weights of b and c, then of a.
      const double wb = (px * vy - vx * py) * inv_area2;
      const double wc = (ux * py - px * uy) * inv_area2;
      const double wa = 1.0 - wb - wc;
      if (wa < -kEdgeTolerance || wb < -kEdgeTolerance || wc < -kEdgeTolerance) continue;
      const double z = wa * a.z() + wb * b.z() + wc * c.z();
      double& out = heights_mm(iy, ix);
      if (std::isnan(out) || z > out) out = z;
    }
  }
}

}  // namespace

Eigen::MatrixXd rasterize_top_view(const Mesh& mesh, const Eigen::Matrix3Xd& x, const SessionGrid& grid) {
  if (x.cols() != mesh.num_points())
    throw std::invalid_argument("rasterize_top_view: positions have " + std::to_string(x.cols()) +
                                " columns, the mesh has " + std::to_string(mesh.num_points()) + " points");
  if (grid.nx < 1 || grid.ny < 1 || !(grid.dx_mm > 0.0) || !(grid.dy_mm > 0.0))
    throw std::invalid_argument("rasterize_top_view: the grid must have nx, ny >= 1 and dx_mm, dy_mm > 0");

  Eigen::MatrixXd heights_mm =
      Eigen::MatrixXd::Constant(grid.ny, grid.nx, std::numeric_limits<double>::quiet_NaN());
  const Eigen::Matrix3Xd x_mm = 1000.0 * x;
  const auto vertex = [&](int i, int j) -> Eigen::Vector3d { return x_mm.col(mesh.index(i, j)); };

  // Each square split along its (i, j)-(i+1, j+1) diagonal.
  for (int i = 0; i + 1 < mesh.point_rows(); ++i) {
    for (int j = 0; j + 1 < mesh.point_cols(); ++j) {
      const Eigen::Vector3d p00 = vertex(i, j), p01 = vertex(i, j + 1);
      const Eigen::Vector3d p10 = vertex(i + 1, j), p11 = vertex(i + 1, j + 1);
      draw_triangle(p00, p01, p11, grid, heights_mm);
      draw_triangle(p00, p11, p10, grid, heights_mm);
    }
  }
  return heights_mm;
}

}  // namespace hj
