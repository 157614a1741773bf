// Comparing a depth-camera frame with a goal as height fields: the goal's
// height at each mesh point's rest (x, y) against the frame interpolated
// there. A domed membrane pulls its points sideways, but a camera sees only
// heights, so the surface is compared where the goal says it should be, not
// where the points went (docs/render.md, "How a capture is compared").
#pragma once

#include <Eigen/Core>

#include "metrics/correlation.h"
#include "model/mesh.h"

namespace hj {

// Where a frame's samples lie: sample (ix, iy) at (x0 + ix dx, y0 + iy dy), mm.
struct FrameGrid {
  int nx = 0, ny = 0;
  double x0_mm = 0.0, y0_mm = 0.0, dx_mm = 1.0, dy_mm = 1.0;
};

// ((R p + 1) x (C p + 1)): the frame (ny x nx, NaN = not seen) bilinearly
// interpolated at each point's rest position, the NaN samples among the four
// around it left out of the weights; NaN where all four are NaN or the point
// lies off the grid.
// @throws std::invalid_argument when the frame's shape is not the grid's or
//         the spacing is not positive.
Eigen::MatrixXd frame_at_rest_points(const Mesh& mesh, const Eigen::MatrixXd& frame_mm, const FrameGrid& grid);

struct HeightError {
  double mae_mm = 0.0;   // mean |measured - reference|
  double rmse_mm = 0.0;
  Correlation correlation;  // Pearson's r over the same points
  int points = 0;        // finite in both
};

// Over the entries finite in both.
// @throws std::invalid_argument when the shapes differ or no entry is finite in both.
HeightError height_error(const Eigen::MatrixXd& reference_mm, const Eigen::MatrixXd& measured_mm);

// A camera tilted and offset against the device (sensor_tilt's parameters:
// tilts in mrad about the array's centre, offset in mm). The clamped edge is
// at height 0 whatever the surface does, so what a frame shows there is the
// camera's plane: a least-squares plane through the edge points' measured
// heights calibrates it out, instead of the loop copying it into the surface.
struct CameraPlane {
  double tilt_x_mrad = 0.0, tilt_y_mrad = 0.0, offset_mm = 0.0;
  int points = 0;  // edge points seen
};
// @throws std::invalid_argument when the shape is not the mesh's or fewer
//         than 3 edge points were seen.
CameraPlane fit_camera_plane(const Mesh& mesh, const Eigen::MatrixXd& measured_mm);
// measured_mm with the plane taken out (NaN stays NaN).
Eigen::MatrixXd without_camera_plane(const Mesh& mesh, const Eigen::MatrixXd& measured_mm, const CameraPlane& plane);

// Iterative learning control on a planner's targets: each entry moved by
// gain times the measured error of the last run, targets + gain (goal -
// measured); an entry whose measurement is NaN keeps its target.
// @throws std::invalid_argument when the shapes differ.
Eigen::MatrixXd learned_targets(const Eigen::MatrixXd& targets_mm, const Eigen::MatrixXd& goal_mm,
                                const Eigen::MatrixXd& measured_mm, double gain);

}  // namespace hj
