#include "model/mesh.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace hj {

namespace {

void check_geometry(const ArrayGeometry& g) {
  if (g.rows < 1) throw std::invalid_argument("array rows must be at least 1, got " + std::to_string(g.rows));
  if (g.cols < 1) throw std::invalid_argument("array cols must be at least 1, got " + std::to_string(g.cols));
  if (g.segments < 2)
    throw std::invalid_argument("segments per cell edge (p) must be at least 2, got " + std::to_string(g.segments));
  if (!std::isfinite(g.cell_size_m) || g.cell_size_m <= 0.0)
    throw std::invalid_argument("cell size must be a positive length in metres, got " + std::to_string(g.cell_size_m));
  const double points = double(g.rows * double(g.segments) + 1) * double(g.cols * double(g.segments) + 1);
  if (points > Mesh::kMaxPoints)
    throw std::invalid_argument("array of " + std::to_string(g.rows) + " x " + std::to_string(g.cols) +
                                " cells at p = " + std::to_string(g.segments) + " has " +
                                std::to_string(static_cast<long long>(points)) + " mesh points, over the limit of " +
                                std::to_string(Mesh::kMaxPoints));
}

}  // namespace

Mesh::Mesh(const ArrayGeometry& geometry) : geometry_(geometry) {
  check_geometry(geometry_);
  const int p = segments();
  kinds_.resize(num_points());
  cell_of_.assign(num_points(), -1);
  cell_interior_.resize(num_cells());
  for (int i = 0; i < point_rows(); ++i) {
    for (int j = 0; j < point_cols(); ++j) {
      const int idx = index(i, j);
      if (i == 0 || j == 0 || i == point_rows() - 1 || j == point_cols() - 1) {
        kinds_[idx] = PointKind::kBoundary;
      } else if (i % p == 0 && j % p == 0) {
        kinds_[idx] = PointKind::kNode;
      } else if (i % p == 0 || j % p == 0) {
        kinds_[idx] = PointKind::kBorder;
      } else {
        kinds_[idx] = PointKind::kInterior;
        const int cell = cell_index(i / p, j / p);
        cell_of_[idx] = cell;
        cell_interior_[cell].push_back(idx);
      }
    }
  }
}

Eigen::Matrix3Xd Mesh::rest_positions() const {
  Eigen::Matrix3Xd x(3, num_points());
  const double h = spacing();
  for (int i = 0; i < point_rows(); ++i)
    for (int j = 0; j < point_cols(); ++j) x.col(index(i, j)) << j * h, i * h, 0.0;
  return x;
}

}  // namespace hj
