// Goal heights at the mesh points: the goal image stretched over the array's
// rectangle, area-averaged over each point's footprint (NaN-aware), then
// scaled so the lowest point is 0 and the highest max_height_mm.
#pragma once

#include <Eigen/Core>

#include "model/mesh.h"
#include "shapes/height_map.h"

namespace hj {

// Default relief of a goal, in mm from its lowest to its highest point. As in
// the paper, it scales with the array's length dimensions: kReliefPerShortSide
// times the array's shorter side (38 mm cells: 10 mm a cell, so 30 mm on the
// 3 x 4 prototype, 90 mm on 9 x 12). A chosen default, not a device limit.
constexpr double kReliefPerShortSide = 30.0 / 114.0;
double default_relief_mm(const ArrayGeometry& geometry);
// requested_mm if positive, else the default relief of the array.
double relief_or_default_mm(double requested_mm, const ArrayGeometry& geometry);

// Returns (R*p+1 x C*p+1) heights in mm, element (i, j) for mesh point (i, j)
// (i along +y, j along +x). The image covers the array's rectangle exactly
// (stretched if the aspect ratios differ; crop first to keep them): image
// column 0 at x = 0, the image's BOTTOM row at y = 0, so mesh row i = 0 is
// the bottom of the image.
// Point (i, j)'s footprint is the square of side h around it, clipped to the
// rectangle; its value is the overlap-area-weighted mean of the valid pixels
// in it. A footprint with no valid pixel takes the value of the valid pixel
// nearest to the point (in pixels). Then heights are scaled linearly to
// [0, max_height_mm]; a flat goal gives all zeros.
// @throws std::invalid_argument on an empty goal, one with no valid pixel or
//         an infinite value, or max_height_mm not positive and finite.
Eigen::MatrixXd resample_to_mesh(const HeightMap& goal, const Mesh& mesh, double max_height_mm);
// The same at the array's default relief.
Eigen::MatrixXd resample_to_mesh(const HeightMap& goal, const Mesh& mesh);

}  // namespace hj
