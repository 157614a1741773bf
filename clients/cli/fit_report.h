// How a fit is written down for people: one line per parameter, shared by
// the fit and diagnose commands (the JSON and the notes on loose parameters
// are the library's: calib/calibration_json.h).
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "calib/calibration_json.h"
#include "calib/least_squares.h"

namespace hj::cli {

// One line per parameter: value +- 95 % half-width, and a note when it is
// loose, at a bound or has no effect on the captures.
std::vector<std::string> parameter_lines(const LeastSquaresResult& fit);

}  // namespace hj::cli
