// Top view of a triangle soup as a height image (seed paper, section 5.3): each
// pixel holds the highest surface z seen from above at its centre; what folds
// underneath is lost. A z-buffer rasteriser, kept apart from file reading.
#pragma once

#include <Eigen/Core>

#include <array>
#include <vector>

namespace hj {

using Triangle3d = std::array<Eigen::Vector3d, 3>;

struct TopView {
  // (rows x cols): row 0 = largest y (north), column 0 = smallest x (west);
  // raw z of the highest surface at the pixel centre, NaN where none is seen.
  Eigen::MatrixXd z;
  double x_min = 0.0;       // west edge of column 0
  double y_max = 0.0;       // north edge of row 0
  double pixel_size = 0.0;  // side of a (square) pixel, in the mesh's units
};

// Renders the triangles' xy projections on a grid of `resolution` square
// pixels along the longer side of their xy bounding box (centred on it),
// keeping the largest barycentrically interpolated z per pixel centre. Edges
// are inclusive with a small tolerance, so shared edges leave no cracks;
// triangles seen edge-on (zero projected area) cover nothing.
// @pre every coordinate finite.
// @throws std::invalid_argument if resolution < 1, there are no triangles or
//         their xy bounding box has zero width and height.
TopView render_top_view(const std::vector<Triangle3d>& triangles, int resolution);

}  // namespace hj
