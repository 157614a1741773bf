// How a fit is written down for people: one line per parameter, shared by
// `hapticjam fit` (its terminal output) and the diagnose page (the JSON and
// the notes on loose parameters are calib/calibration_json.h's).
#pragma once

#include <string>
#include <vector>

#include "calib/least_squares.h"

namespace hj {

// One line per parameter: value +- 95 % half-width, and a note when it is
// loose, at a bound or has no effect on the captures.
std::vector<std::string> parameter_lines(const LeastSquaresResult& fit);

}  // namespace hj
