// The torsional (bending) springs of the interior points of cells: their
// five points, orientation and, in a jammed cell, rest angle phi_eq.
#pragma once

#include <array>

#include "model/device_state.h"
#include "model/mesh.h"
#include "sim/bend_angle.h"

namespace hj {

struct BendSpring {
  std::array<int, 5> p;  // A, i, B, C1, C2 (BendPoint order)
  double sigma;          // +1 along x, -1 along y
  int axis;              // 0 along x, 1 along y: row of DeviceState::phi_eq
  double phi_eq;
};

// The two springs of interior point `point`, with rest angles (rad).
inline std::array<BendSpring, 2> bend_springs_at(const Mesh& mesh, int point, double phi_eq_x = 0.0,
                                                 double phi_eq_y = 0.0) {
  const int nc = mesh.point_cols();
  return {BendSpring{{point - 1, point, point + 1, point - nc, point + nc}, 1.0, 0, phi_eq_x},
          BendSpring{{point - nc, point, point + nc, point - 1, point + 1}, -1.0, 1, phi_eq_y}};
}

inline double bend_angle_of(const Eigen::Matrix3Xd& x, const BendSpring& s) {
  return bend_angle(x.col(s.p[0]), x.col(s.p[1]), x.col(s.p[2]), x.col(s.p[3]), x.col(s.p[4]), s.sigma);
}

// Calls fn(spring) for both springs of every interior point of every jammed cell.
template <class Fn>
void for_each_jammed_spring(const Mesh& mesh, const DeviceState& state, Fn&& fn) {
  for (int r = 0; r < mesh.rows(); ++r)
    for (int c = 0; c < mesh.cols(); ++c) {
      if (!state.jammed(mesh, r, c)) continue;
      for (int point : mesh.cell_interior(r, c))
        for (const BendSpring& s : bend_springs_at(mesh, point, state.phi_eq(0, point), state.phi_eq(1, point))) fn(s);
    }
}

}  // namespace hj
