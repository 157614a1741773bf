#include "sim/levelling_crossing.h"

#include <algorithm>
#include <limits>

namespace hj {

std::optional<Eigen::Matrix3Xd> levelling_crossing_start(const ForceModel& model, const DeviceState& before,
                                                         double new_pressure_pa) {
  const bool any_jammed = std::any_of(before.cell_jammed.begin(), before.cell_jammed.end(), [](char c) { return c; });
  const bool any_pinned = std::any_of(before.node_pinned.begin(), before.node_pinned.end(), [](char c) { return c; });
  if (any_jammed || any_pinned) return std::nullopt;
  const double levelling = model.params().levelling_pressure_pa(model.mesh());
  const double old_load = before.pressure_pa - levelling, new_load = new_pressure_pa - levelling;
  if (!(old_load * new_load < 0.0)) return std::nullopt;

  DeviceState trial = before;
  trial.pressure_pa = new_pressure_pa;
  const std::vector<char> fixed = model.fixed_points(trial);
  Eigen::Matrix3Xd f;
  double best_norm = std::numeric_limits<double>::infinity();
  Eigen::Matrix3Xd best;
  // Large deflections change little with the load (9 x 12: 0.3 kPa down
  // and 1.7 kPa up give the same depth), small ones more: try a few scales.
  for (double scale : {0.6, 0.8, 1.0, 1.25}) {
    trial.x = before.x;
    for (Eigen::Index p = 0; p < trial.x.cols(); ++p)
      if (!fixed[p]) trial.x(2, p) = -scale * before.x(2, p);
    model.forces(trial, trial.x, f);
    double norm = 0.0;
    for (Eigen::Index p = 0; p < f.cols(); ++p)
      if (!fixed[p]) norm += f.col(p).squaredNorm();
    if (norm < best_norm) {
      best_norm = norm;
      best = trial.x;
    }
  }
  if (!std::isfinite(best_norm)) return std::nullopt;
  return best;
}

}  // namespace hj
