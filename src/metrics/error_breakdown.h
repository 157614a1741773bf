// Where a plan's remaining error lies, in the three places the seed paper
// names: features at the clamped edge (the border is held at height 0),
// valleys that fall between nodes (only nodes can be pinned low), and
// detail smaller than a cell (one cell makes a smooth dome or bowl between
// its corners). Correlation ignores scale and offset, so the error is the
// goal minus the best affine fit of the predicted surface to it.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "model/mesh.h"

namespace hj {

struct ErrorPlace {
  std::string name;          // "clamped_edge", "valley_between_nodes", "sub_cell_detail", "elsewhere"
  double error_share = 0.0;  // of the residual's sum of squares
  double area_share = 0.0;   // of the mesh points
  double rms_mm = 0.0;       // the residual's RMS over these points (0 when none)
};

struct ErrorBreakdown {
  // In the order above; each mesh point counts in the first place it belongs to.
  std::vector<ErrorPlace> places;
  double rms_mm = 0.0;  // over every point
  // The place whose error share most exceeds its area share.
  std::string dominant() const;
};

// goal_mm and predicted_mm: ((R p + 1) x (C p + 1)) heights at the mesh points.
// A point is at the clamped edge within half a cell of the border; near a
// valley between nodes within half a cell of a goal valley (a local minimum
// at least 5 % of the relief below the median of the ring half a cell
// around it) that lies more than a quarter cell from every node; sub-cell detail where the
// goal departs from its cell's best smooth shape (bilinear between the
// corners plus one dome) by more than 5 % of the relief.
// @throws std::invalid_argument when the shapes are not the mesh's or hold non-finite values.
ErrorBreakdown error_breakdown(const Mesh& mesh, const Eigen::MatrixXd& goal_mm, const Eigen::MatrixXd& predicted_mm);

}  // namespace hj
