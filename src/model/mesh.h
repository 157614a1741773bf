// The mesh of a Haptic Jamming array: R x C square cells of side s, each edge
// split into p segments, giving (R*p+1) x (C*p+1) points (docs/model.md,
// "Geometry"). Point (i, j): row i along +y, column j along +x.
#pragma once

#include <Eigen/Core>
#include <vector>

namespace hj {

// What a user states about an array; validated by Mesh.
struct ArrayGeometry {
  int rows = 3;                 // R, cells along +y
  int cols = 4;                 // C, cells along +x
  double cell_size_m = 0.038;   // s
  int segments = 4;             // p, segments per cell edge
};

enum class PointKind { kBoundary, kNode, kBorder, kInterior };

// Immutable index maps of the mesh. Throws std::invalid_argument on a
// geometry that names no sensible mesh.
class Mesh {
 public:
  // Upper bound on points, so an absurd size is refused instead of
  // exhausting memory.
  static constexpr int kMaxPoints = 4'000'000;

  explicit Mesh(const ArrayGeometry& geometry);

  const ArrayGeometry& geometry() const { return geometry_; }
  int rows() const { return geometry_.rows; }
  int cols() const { return geometry_.cols; }
  int segments() const { return geometry_.segments; }
  double cell_size() const { return geometry_.cell_size_m; }
  double spacing() const { return geometry_.cell_size_m / geometry_.segments; }  // h
  int point_rows() const { return rows() * segments() + 1; }  // along y
  int point_cols() const { return cols() * segments() + 1; }  // along x
  int num_points() const { return point_rows() * point_cols(); }
  double area() const { return rows() * cols() * cell_size() * cell_size(); }
  // Flat area per point, A_spp = (R s)(C s) / N.
  double area_per_point() const { return area() / num_points(); }

  int index(int i, int j) const { return i * point_cols() + j; }
  int row_of(int idx) const { return idx / point_cols(); }
  int col_of(int idx) const { return idx % point_cols(); }
  PointKind kind(int idx) const { return kinds_[idx]; }
  bool is_boundary(int idx) const { return kinds_[idx] == PointKind::kBoundary; }

  int num_cells() const { return rows() * cols(); }
  int cell_index(int r, int c) const { return r * cols() + c; }
  bool valid_cell(int r, int c) const { return r >= 0 && r < rows() && c >= 0 && c < cols(); }
  // Interior points of cell (r, c): (p-1)^2 of them.
  const std::vector<int>& cell_interior(int r, int c) const { return cell_interior_[cell_index(r, c)]; }
  // Cell of an interior point, -1 otherwise.
  int cell_of(int idx) const { return cell_of_[idx]; }

  // Pinnable nodes (a, b), a in 1..R-1, b in 1..C-1.
  bool valid_node(int a, int b) const { return a >= 1 && a < rows() && b >= 1 && b < cols(); }
  int node_point(int a, int b) const { return index(a * segments(), b * segments()); }
  int num_nodes() const { return (rows() - 1) * (cols() - 1); }
  int node_index(int a, int b) const { return (a - 1) * (cols() - 1) + (b - 1); }

  // Rest positions, (3 x N): point (i, j) at (j h, i h, 0).
  Eigen::Matrix3Xd rest_positions() const;

 private:
  ArrayGeometry geometry_;
  std::vector<PointKind> kinds_;
  std::vector<int> cell_of_;
  std::vector<std::vector<int>> cell_interior_;
};

}  // namespace hj
