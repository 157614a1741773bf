// Aligning a goal with the array's nodes, the seed paper's future work
// (section 6: "rescale and translate the goal so key features align with the
// nodes"): the window a goal is taken from, moved by up to half a cell and
// shrunk a little, scored by how far the goal's valleys fall from the nodes.
// The surface makes sharp valleys only at nodes (which can be pinned) or the
// boundary, never mid-cell, where an unjammed cell bulges.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "model/mesh.h"
#include "shapes/height_map.h"
#include "shapes/region.h"

namespace hj {

// A window of the source relative to the window the unaligned goal is taken
// from: its sides scaled by `scale` about its centre, then moved by
// shift_x_cells, shift_y_cells cells of the array (a cell being the scaled
// window's width / C and height / R). +x moves the window towards higher
// image columns, +y towards the image's top (the array's +y), so the goal's
// features move the other way on the array.
struct GoalTransform {
  double shift_x_cells = 0.0, shift_y_cells = 0.0, scale = 1.0;
  bool is_identity() const { return shift_x_cells == 0.0 && shift_y_cells == 0.0 && scale == 1.0; }
};

// The bounds and grid of the transforms tried.
struct AlignOptions {
  double max_shift_cells = 0.5;  // |shift_x_cells|, |shift_y_cells| at most this, in [0, 0.5]
  double min_scale = 0.8;        // 0 < min_scale <= max_scale <= 1 (the window stays
  double max_scale = 1.0;        // no larger than the original, inside the source)
  int shift_steps = 4;           // shifts on a grid of max_shift_cells / shift_steps each way, >= 1
  int scale_steps = 4;           // scales max_scale down to min_scale in this many steps, >= 1
  // @throws std::invalid_argument naming the field (AlignOptions.min_scale ...)
  //         that is NaN, out of its range, or inconsistent with another.
  void validate() const;
};

// A valley of a goal on the mesh: an interior mesh point lower than its eight
// neighbours (of equal lowest neighbours, the first in row-major order),
// located to a fraction of a point by a parabola through it and its
// neighbours along x and along y (halfway between two equal points).
struct GoalValley {
  double x_cells = 0.0, y_cells = 0.0;  // from the array's corner at (0, 0)
  double depth_mm = 0.0;                // mean of the eight neighbours minus the point
  double node_distance_cells = 0.0;     // to the nearest node (cell corner)
};

// The valleys of goal_mm ((R p + 1) x (C p + 1), mm, row i along +y).
std::vector<GoalValley> goal_valleys(const Eigen::MatrixXd& goal_mm, int segments);

// The criterion: the sum over the valleys of depth_mm x node_distance_cells
// (mm x cells); 0 when every valley sits on a node.
double valley_cost(const std::vector<GoalValley>& valleys);

struct AlignmentCandidate {
  GoalTransform transform;
  Region window;             // the source's pixels it takes (fractions = false)
  Eigen::MatrixXd goal_mm;   // that window resampled to the mesh at the relief
  double valley_cost = 0.0;  // valley_cost(goal_valleys(goal_mm))
  int valleys = 0;
};

// The pixel window of `transform` applied to `window` (pixels of the source,
// fractions = false) for `geometry`; edges rounded to whole pixels, so the
// window may reach outside the source (see alignment_candidates).
Region transformed_window(const Region& window, const GoalTransform& transform, const ArrayGeometry& geometry);

// Every transform on the options' grid whose window lies inside the source
// and holds valid pixels, one per distinct pixel window (the smallest move
// kept), each resampled to the mesh at relief_mm and scored. The identity
// comes first, the rest follow by valley cost, lowest first.
// @throws std::invalid_argument on bad options, a window that is not a pixel
//         region inside the source, or relief_mm not positive.
std::vector<AlignmentCandidate> alignment_candidates(const HeightMap& source, const Region& window, const Mesh& mesh,
                                                     double relief_mm, const AlignOptions& options);

}  // namespace hj
