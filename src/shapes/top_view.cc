#include "shapes/top_view.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace hj {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
// A pixel centre within this barycentric margin outside a triangle still counts
// as inside it, so samples on a shared edge hit at least one of its triangles.
constexpr double kEdgeTolerance = 1e-9;
// Projected triangles with |2 x area| below this fraction of the squared grid
// extent are edge-on (vertical walls) and skipped.
constexpr double kMinRelativeArea = 1e-14;

double cross2(const Eigen::Vector2d& a, const Eigen::Vector2d& b) { return a.x() * b.y() - a.y() * b.x(); }

// Rasterises one triangle into `view`, keeping the maximum z per pixel.
void draw(const Triangle3d& t, double min_area2, TopView& view) {
  const Eigen::Vector2d a = t[0].head<2>(), b = t[1].head<2>(), c = t[2].head<2>();
  const double area2 = cross2(b - a, c - a);
  if (std::abs(area2) < min_area2) return;
  const auto rows = view.z.rows(), cols = view.z.cols();
  const double px = view.pixel_size;

  // Pixel bounding box: centres x = x_min + (col + 0.5) px, y = y_max - (row + 0.5) px.
  const double lo_x = std::min({a.x(), b.x(), c.x()}), hi_x = std::max({a.x(), b.x(), c.x()});
  const double lo_y = std::min({a.y(), b.y(), c.y()}), hi_y = std::max({a.y(), b.y(), c.y()});
  const auto c0 = std::max<Eigen::Index>(0, Eigen::Index(std::floor((lo_x - view.x_min) / px - 0.5)));
  const auto c1 = std::min<Eigen::Index>(cols - 1, Eigen::Index(std::ceil((hi_x - view.x_min) / px - 0.5)));
  const auto r0 = std::max<Eigen::Index>(0, Eigen::Index(std::floor((view.y_max - hi_y) / px - 0.5)));
  const auto r1 = std::min<Eigen::Index>(rows - 1, Eigen::Index(std::ceil((view.y_max - lo_y) / px - 0.5)));

  for (Eigen::Index r = r0; r <= r1; ++r) {
    for (Eigen::Index col = c0; col <= c1; ++col) {
      const Eigen::Vector2d p(view.x_min + (double(col) + 0.5) * px, view.y_max - (double(r) + 0.5) * px);
      // Barycentric weights of a, b, c at p.
      const double wa = cross2(c - b, p - b) / area2;
      const double wb = cross2(a - c, p - c) / area2;
      const double wc = 1.0 - wa - wb;
      if (wa < -kEdgeTolerance || wb < -kEdgeTolerance || wc < -kEdgeTolerance) continue;
      const double z = wa * t[0].z() + wb * t[1].z() + wc * t[2].z();
      double& cell = view.z(r, col);
      if (std::isnan(cell) || z > cell) cell = z;
    }
  }
}

}  // namespace

TopView render_top_view(const std::vector<Triangle3d>& triangles, int resolution) {
  if (resolution < 1)
    throw std::invalid_argument("top view resolution must be at least 1 pixel, got " + std::to_string(resolution));
  if (triangles.empty()) throw std::invalid_argument("top view of no triangles");

  // xy bounding box of all vertices.
  Eigen::Vector2d lo = triangles[0][0].head<2>(), hi = lo;
  for (const auto& t : triangles)
    for (const auto& v : t) {
      lo = lo.cwiseMin(v.head<2>());
      hi = hi.cwiseMax(v.head<2>());
    }
  const Eigen::Vector2d size = hi - lo;
  const double longer = size.maxCoeff();
  if (!(longer > 0.0)) throw std::invalid_argument("top view of triangles with no horizontal extent");

  // Square pixels, `resolution` along the longer side; the grid is centred on the box.
  TopView view;
  view.pixel_size = longer / resolution;
  const auto pixels_along = [&](double extent) {
    return std::clamp(Eigen::Index(std::ceil(extent / view.pixel_size - 1e-9)), Eigen::Index(1), Eigen::Index(resolution));
  };
  const Eigen::Index cols = pixels_along(size.x()), rows = pixels_along(size.y());
  view.x_min = 0.5 * (lo.x() + hi.x()) - 0.5 * double(cols) * view.pixel_size;
  view.y_max = 0.5 * (lo.y() + hi.y()) + 0.5 * double(rows) * view.pixel_size;
  view.z = Eigen::MatrixXd::Constant(rows, cols, kNaN);

  // Z-buffer: every triangle, highest z wins.
  const double min_area2 = kMinRelativeArea * longer * longer;
  for (const auto& t : triangles) draw(t, min_area2, view);
  return view;
}

}  // namespace hj
