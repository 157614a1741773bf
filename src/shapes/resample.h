// Goal heights at the mesh points: the goal image stretched over the array's
// rectangle, area-averaged over each point's footprint (NaN-aware), then
// scaled so the lowest point is 0 and the highest max_height_mm.
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <string>

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

// How a goal's values become heights on the display: stretched to a relief
// (resample_to_mesh), or taken at face value as mm above the plane of the
// clamped edge (negative allowed), for a user who knows the surface.
enum class GoalHeights { kScaled, kAbsolute };
// "scaled" or "absolute"; std::invalid_argument otherwise.
GoalHeights parse_goal_heights(const std::string& name);

// Absolute heights are for goals whose values are mm: a CSV or a (float)
// TIFF. @throws std::invalid_argument naming the file for another format.
void check_absolute_goal_format(const std::filesystem::path& file);

// The goal at face value, mm per mesh point, not rescaled. A goal of exactly
// (R p + 1) x (C p + 1) values is the goal at the mesh points (row 0 = the
// top, i.e. mesh row R p, as for any image); any other size is area-averaged
// as resample_to_mesh does, without the scaling.
// @throws std::invalid_argument as resample_to_mesh, and for a NaN value in
//         a goal given at the mesh points (naming its row and column).
Eigen::MatrixXd absolute_to_mesh(const HeightMap& goal, const Mesh& mesh);

// The goal per mesh point as `heights` says (max_height_mm only for kScaled,
// 0 = the array's default relief).
Eigen::MatrixXd goal_to_mesh(const HeightMap& goal, const Mesh& mesh, GoalHeights heights, double max_height_mm);

}  // namespace hj
