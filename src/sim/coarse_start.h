// A start for a large free net's levelling crossing (levelling_crossing.h)
// from the same settle on a mesh with fewer segments per cell edge. k is the
// net's 2-D modulus and does not change with p (docs/model.md), so the
// coarse mesh is the same surface, discretised coarser; its settle costs a
// fraction of the fine one's per step, and its dome, resampled to the fine
// mesh, lies within a few Newton steps of the fine dome. 9 x 12, p = 4,
// rest to 2 kPa: 9 fine steps after 16 at p = 2 (each about a tenth of a
// fine one), against 24 from the mirrored sag; and the dome reached is the
// one the paper's explicit Euler reaches (7.9e-6 mm apart), while the
// mirrored sag leads to a neighbouring one 2.0 mm away near the edges.
#pragma once

#include <Eigen/Core>
#include <optional>

#include "model/device_state.h"
#include "sim/force_model.h"
#include "sim/static_solver.h"

namespace hj {

// Segments of the coarse mesh for a fine mesh of `segments` (half of them),
// or 0 where there is none coarser than the minimum of 2.
int coarse_segments(int segments);

// Positions (or any point field) on mesh `to` from those on mesh `from`
// (same rows, columns and cell size, any segments), interpolated
// bilinearly in the rest grid.
Eigen::Matrix3Xd resample_to_mesh(const Mesh& from, const Eigen::Matrix3Xd& x, const Mesh& to);

// What the coarse settle gives the fine one.
struct CoarseStart {
  Eigen::Matrix3Xd x;  // the start, on the fine mesh
  // The mode the coarse settle pushed along without reaching another
  // equilibrium (SettleMemory), resampled to the fine free DOFs and unit;
  // empty if none. The fine settle need not push along it again: on the
  // 9 x 12 dome at 2 kPa the two meshes' shear modes overlap by 0.998, and
  // the fine push costs 12 fine steps where the coarse one costs 12 coarse.
  Eigen::VectorXd marginal_mode;
};

// The coarse model's settle of the crossing (fast control only; stability
// checked as `options` say), resampled to the fine mesh; or nothing when
// `before` is not a free net crossing levelling or the coarse settle does
// not converge. `coarse` is the fine model's effects on the coarser mesh.
// Throws SettleInterrupted if options.interrupted says so.
std::optional<CoarseStart> coarse_mesh_start(const ForceModel& fine, const ForceModel& coarse,
                                             const DeviceState& before, double new_pressure_pa,
                                             const StaticSolverOptions& options);

}  // namespace hj
