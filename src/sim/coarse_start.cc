#include "sim/coarse_start.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "sim/levelling_crossing.h"
#include "sim/stiffness_matrix.h"

namespace hj {

int coarse_segments(int segments) { return segments >= 4 ? segments / 2 : 0; }

Eigen::Matrix3Xd resample_to_mesh(const Mesh& from, const Eigen::Matrix3Xd& x, const Mesh& to) {
  if (from.rows() != to.rows() || from.cols() != to.cols() || from.cell_size() != to.cell_size())
    throw std::invalid_argument("resample_to_mesh: the meshes differ in more than their segments");
  if (x.cols() != from.num_points())
    throw std::invalid_argument("resample_to_mesh: " + std::to_string(x.cols()) + " positions for a mesh of " +
                                std::to_string(from.num_points()) + " points");
  const double ratio = static_cast<double>(from.segments()) / to.segments();
  Eigen::Matrix3Xd out(3, to.num_points());
  for (int i = 0; i < to.point_rows(); ++i) {
    const double u = i * ratio;
    const int i0 = std::min(static_cast<int>(std::floor(u)), from.point_rows() - 2);
    const double fu = u - i0;
    for (int j = 0; j < to.point_cols(); ++j) {
      const double v = j * ratio;
      const int j0 = std::min(static_cast<int>(std::floor(v)), from.point_cols() - 2);
      const double fv = v - j0;
      out.col(to.index(i, j)) = (1 - fu) * ((1 - fv) * x.col(from.index(i0, j0)) + fv * x.col(from.index(i0, j0 + 1))) +
                                fu * ((1 - fv) * x.col(from.index(i0 + 1, j0)) + fv * x.col(from.index(i0 + 1, j0 + 1)));
    }
  }
  return out;
}

std::optional<CoarseStart> coarse_mesh_start(const ForceModel& fine, const ForceModel& coarse,
                                             const DeviceState& before, double new_pressure_pa,
                                             const StaticSolverOptions& options) {
  if (options.fast_iterations == 0) return std::nullopt;
  // The coarse state is the image of a free net only: no jams, no pins.
  if (std::any_of(before.cell_jammed.begin(), before.cell_jammed.end(), [](char c) { return c; }) ||
      std::any_of(before.node_pinned.begin(), before.node_pinned.end(), [](char c) { return c; }))
    return std::nullopt;
  DeviceState state = DeviceState::flat(coarse.mesh());
  state.x = resample_to_mesh(fine.mesh(), before.x, coarse.mesh());
  state.pressure_pa = before.pressure_pa;
  const std::optional<Eigen::Matrix3Xd> mirrored = levelling_crossing_start(coarse, state, new_pressure_pa);
  if (!mirrored) return std::nullopt;
  state.x = *mirrored;
  state.pressure_pa = new_pressure_pa;
  StaticSolverOptions fast = options;
  fast.careful = false;
  SettleMemory memory;
  const SettleReport report = settle_static(coarse, state, fast, &memory);
  if (!report.converged) return std::nullopt;
  CoarseStart start{resample_to_mesh(coarse.mesh(), state.x, fine.mesh()), {}};
  if (report.marginal && memory.marginal_mode.size() > 0) {
    // Free DOFs in the solver's order (StiffnessMatrix), without a pattern.
    auto no_blocks = [](StiffnessSink&) {};
    const StiffnessMatrix coarse_dofs(coarse.mesh(), coarse.fixed_points(state), no_blocks);
    DeviceState after = before;
    after.pressure_pa = new_pressure_pa;
    const StiffnessMatrix fine_dofs(fine.mesh(), fine.fixed_points(after), no_blocks);
    start.marginal_mode =
        fine_dofs.gather(resample_to_mesh(coarse.mesh(), coarse_dofs.scatter(memory.marginal_mode), fine.mesh()));
    const double norm = start.marginal_mode.norm();
    if (norm > 0.0) start.marginal_mode /= norm;
    else start.marginal_mode.resize(0);
  }
  return start;
}

}  // namespace hj
