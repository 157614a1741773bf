// The parameters a fit adjusts, taken from the effect registry (each
// effect's ParameterSpec: name, unit, default, bounds), so that a new effect
// is fittable with no code here: the baseline's (SurfaceParameters fields)
// followed by those of each switched-on effect.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "calib/model_params.h"

namespace hj {

struct FitParameter {
  std::string effect;  // registry name of the effect that reads it
  ParameterSpec spec;
  bool surface = false;  // a baseline SurfaceParameters field

  // "spring_k" for the baseline, "bending.kappa_bend" for an effect.
  std::string qualified_name() const { return surface ? spec.name : effect + "." + spec.name; }
};

// False for a parameter of unit "cell" (cell_defect's row and col): it
// names a cell of the array, a discrete choice no fit can move; diagnose
// searches it (cell_search.h).
bool is_fitted(const ParameterSpec& spec);

// The baseline's parameters, then each of `effects`' fitted ones in order.
// @throws std::invalid_argument naming an unknown effect.
std::vector<FitParameter> fit_parameters(const std::vector<std::string>& effects);

// The note of a search that moved one parameter, e.g. "bending.kappa_bend
// 0 -> 0.003 (sum of squares -67 %)" (effect_scan.h, optimum_probe.h);
// without a gain, "(the start does not replay)".
std::string parameter_move_note(const FitParameter& p, double from, double to, std::optional<double> ssr_gain);

double parameter_value(const ModelParams& params, const FitParameter& p);
// Sets the value, switching the effect on (with its defaults) if it is off.
void set_parameter_value(ModelParams& params, const FitParameter& p, double value);

// `params` with every effect of `effects` switched on; those that were off
// take their registry defaults.
ModelParams with_effects(ModelParams params, const std::vector<std::string>& effects);

}  // namespace hj
