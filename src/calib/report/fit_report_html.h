// report.html of a fit, for people: the levelling estimate of the mass,
// Algorithm 1's stiffnesses, the joint least squares with every parameter's
// value and 95 % interval, the notes on loose parameters and the held-out
// error. Shared by `hapticjam fit` and CalibrationService.Fit.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "calib/fit_model.h"

namespace hj {

// @param dataset_name  shown in the title
// @param heldout       {"sessions": [...], "rmse_mm"?: ...} as params.json's "heldout"
std::string fit_report_html(const std::string& dataset_name, const FitReport& report, const nlohmann::json& heldout);

}  // namespace hj
