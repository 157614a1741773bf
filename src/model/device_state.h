// The mutable state of a device: chamber pressure, jammed cells with their
// rest bend angles, pinned nodes, and every point's position
// (docs/model.md, "States and actions").
#pragma once

#include <Eigen/Core>
#include <vector>

#include "model/mesh.h"

namespace hj {

struct DeviceState {
  double pressure_pa = 0.0;           // gauge, 0..P_max
  Eigen::Matrix3Xd x;                 // (3 x N) positions, m
  std::vector<char> cell_jammed;      // (R*C), by Mesh::cell_index
  std::vector<char> node_pinned;      // ((R-1)*(C-1)), by Mesh::node_index
  // Rest bend angles phi_eq of the two bending springs at each point, set
  // when its cell is jammed: (2 x N), row 0 along x, row 1 along y; rad.
  Eigen::Matrix2Xd phi_eq;

  // Flat, unpressurised, nothing jammed or pinned (not yet settled).
  static DeviceState flat(const Mesh& mesh);

  bool jammed(const Mesh& mesh, int r, int c) const { return cell_jammed[mesh.cell_index(r, c)] != 0; }
  bool pinned(const Mesh& mesh, int a, int b) const { return node_pinned[mesh.node_index(a, b)] != 0; }
  // A point that does not move: the clamped edge or a pinned node.
  std::vector<char> fixed_points(const Mesh& mesh) const;
};

}  // namespace hj
