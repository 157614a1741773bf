// Folds in the deformed mesh: a point whose two spring segments along x (or
// y) turn back on each other by more than 90 degrees. There the central
// differences of the Eq. 3 normal nearly cancel, so the pressure direction
// and its derivative are ill-defined; settles that end in no equilibrium on
// large arrays (9 x 12 volcano plan, 6 x 8 from-above plan) start from such
// states, so the simulator's error names them.
#pragma once

#include <Eigen/Core>
#include <string>

#include "model/mesh.h"

namespace hj {

struct MeshFolds {
  int count = 0;                // segment pairs bent past 90 degrees
  double sharpest_deg = 0.0;    // the largest bend, degrees (180: folded flat)
  int row = -1, col = -1;       // its mesh point (i, j)
  char axis = 'x';              // along x or y
  // "" without folds, else e.g. "the mesh is folded at 38 places, sharpest
  // 172 degrees at point (31, 25) along x".
  std::string describe() const;
};

// Over the points with both neighbours along an axis (x: 3 x N positions).
MeshFolds find_mesh_folds(const Mesh& mesh, const Eigen::Matrix3Xd& x);

}  // namespace hj
