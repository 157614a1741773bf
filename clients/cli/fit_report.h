// How a fit is written down: the uncertainty of each parameter as JSON and
// as sentences (which ones the data constrain only loosely), shared by the
// fit and diagnose commands.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "calib/least_squares.h"

namespace hj::cli {

// {"spring_k": {"value", "std_error", "ci95": [lo, hi], "unit", "active", "at_bound", "loose",
//  "interval_method"}, ...}; where interval_method is not "linearised", also
// "ci95_linearised": [lo, hi] (value +- 1.96 std_error) and, if an end of
// the profile reached the parameter's bound, "ci95_open": [low, high].
nlohmann::json uncertainties_json(const LeastSquaresResult& fit);

// One line per parameter: value +- 95 % half-width, and a note when it is
// loose, at a bound or has no effect on the captures.
std::vector<std::string> parameter_lines(const LeastSquaresResult& fit);

// Sentences about the parameters that the data constrain only loosely, and
// which one they constrain least (with the relative widths of the others).
std::vector<std::string> loose_notes(const LeastSquaresResult& fit);

}  // namespace hj::cli
