#include "sim/surface_measures.h"

#include "sim/jamming_springs.h"

namespace hj {

double cell_curvature(const Mesh& mesh, const Eigen::Matrix3Xd& x, int r, int c) {
  double sum = 0.0;
  int count = 0;
  for (int p : mesh.cell_interior(r, c))
    for (const BendSpring& s : bend_springs_at(mesh, p)) {
      sum += bend_angle_of(x, s);
      ++count;
    }
  return sum / count;
}

Eigen::MatrixXd cell_curvatures(const Mesh& mesh, const Eigen::Matrix3Xd& x) {
  Eigen::MatrixXd out(mesh.rows(), mesh.cols());
  for (int r = 0; r < mesh.rows(); ++r)
    for (int c = 0; c < mesh.cols(); ++c) out(r, c) = cell_curvature(mesh, x, r, c);
  return out;
}

Eigen::MatrixXd node_heights(const Mesh& mesh, const Eigen::Matrix3Xd& x) {
  Eigen::MatrixXd out(mesh.rows() - 1, mesh.cols() - 1);
  for (int a = 1; a < mesh.rows(); ++a)
    for (int b = 1; b < mesh.cols(); ++b) out(a - 1, b - 1) = x(2, mesh.node_point(a, b));
  return out;
}

Eigen::MatrixXd point_coordinates(const Mesh& mesh, const Eigen::Matrix3Xd& x, int axis) {
  Eigen::MatrixXd out(mesh.point_rows(), mesh.point_cols());
  for (int i = 0; i < mesh.point_rows(); ++i)
    for (int j = 0; j < mesh.point_cols(); ++j) out(i, j) = x(axis, mesh.index(i, j));
  return out;
}

Eigen::MatrixXd point_heights(const Mesh& mesh, const Eigen::Matrix3Xd& x) { return point_coordinates(mesh, x, 2); }

}  // namespace hj
