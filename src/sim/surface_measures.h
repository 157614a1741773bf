// Measures of a settled surface that the planner reads: the curvature of a
// cell (paper Eq. 11: the mean signed bend angle over its interior points,
// both directions) and the heights of the pinnable nodes.
#pragma once

#include <Eigen/Core>

#include "model/device_state.h"
#include "model/mesh.h"

namespace hj {

// Mean signed bend (rad) of cell (r, c); positive when it bulges up.
double cell_curvature(const Mesh& mesh, const Eigen::Matrix3Xd& x, int r, int c);
// (R x C) curvatures, rad.
Eigen::MatrixXd cell_curvatures(const Mesh& mesh, const Eigen::Matrix3Xd& x);
// ((R-1) x (C-1)) node heights z, m; entry (a-1, b-1) is node (a, b).
Eigen::MatrixXd node_heights(const Mesh& mesh, const Eigen::Matrix3Xd& x);
// ((R p + 1) x (C p + 1)) heights z of every point, m.
Eigen::MatrixXd point_heights(const Mesh& mesh, const Eigen::Matrix3Xd& x);
// The same for any coordinate (axis 0: x, 1: y, 2: z), m.
Eigen::MatrixXd point_coordinates(const Mesh& mesh, const Eigen::Matrix3Xd& x, int axis);

}  // namespace hj
