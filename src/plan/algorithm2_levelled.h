// Algorithm 2 that jams no cell while the net still sags below the
// levelling pressure. In the sag every cell is concave, so Algorithm 2 jams
// each goal valley's cell there, and from 5 x 8 up the jammed sag folds at
// every later pressure step (docs/planners.md); jamming only once the net
// domes avoids that regime. Built on Algorithm2Refined: targets scale *
// goal, no pin bisection, the end-pressure scan.
#pragma once

#include <memory>

#include "plan/planner.h"

namespace hj {

std::unique_ptr<Planner> make_algorithm2_levelled(double height_scale = 1.0);

}  // namespace hj
