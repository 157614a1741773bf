// A start for the settle after a set_pressure that carries a free net
// (nothing jammed, nothing pinned) across the levelling pressure M g / area.
// The net load on the membrane then flips sign and the surface goes through
// flat to the other side; flat is where the net has no out-of-plane
// stiffness (no pre-tension), so a settle that starts from the old side
// crawls through it (9 x 12, p = 4, rest to 2 kPa: 650 steps). The branch
// on the other side is close to the mirror image of the old state (9 x 12:
// sag -170.8 mm at 0 Pa, dome +167.0 mm at 2 kPa), so the settle starts
// there. Simulator::apply settles from the old state if this start fails.
#pragma once

#include <Eigen/Core>
#include <optional>

#include "model/device_state.h"
#include "sim/force_model.h"

namespace hj {

// The mirrored start (z -> -s z for the free points, s the scale of a few
// with the smallest residual force), or nothing when the action is not such
// a crossing. `before` is the settled state at the old pressure.
std::optional<Eigen::Matrix3Xd> levelling_crossing_start(const ForceModel& model, const DeviceState& before,
                                                         double new_pressure_pa);

}  // namespace hj
