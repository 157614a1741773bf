// The depth camera's view of a simulated surface (docs/model.md, "Measured
// surfaces"): the deformed mesh, two triangles per square split along the
// (i, j)-(i+1, j+1) diagonal, rasterised from above onto a frame's grid.
#pragma once

#include <Eigen/Core>

#include "calib/session.h"
#include "model/mesh.h"

namespace hj {

// Heights seen from above at the grid's samples, (ny x nx) in mm: at each
// sample, the highest z (linearly interpolated) of the triangles whose xy
// projection covers it, a sample on a shared edge or vertex counting as
// covered; NaN where no triangle covers it. Triangles of zero xy area are
// skipped.
// @param x  (3 x N) positions in metres, column Mesh::index(i, j).
// @throws std::invalid_argument if x has the wrong number of columns or the
//         grid is empty or has a non-positive spacing.
Eigen::MatrixXd rasterize_top_view(const Mesh& mesh, const Eigen::Matrix3Xd& x, const SessionGrid& grid);

}  // namespace hj
