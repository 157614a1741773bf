// A fitted parameter as the calibration and render services send it.
#pragma once

#include "calib/least_squares.h"
#include "hapticjam/v1/calibration_service.pb.h"

namespace hj::server {

// Name, value and unit; the interval too when the parameter was fitted (active).
void estimate_to_proto(const ParameterEstimate& estimate, hapticjam::v1::FittedParameter* out);

}  // namespace hj::server
