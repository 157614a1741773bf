#include "calib/fit_parameters.h"

#include <algorithm>
#include <cstdio>
#include <stdexcept>

namespace hj {

bool is_fitted(const ParameterSpec& spec) { return spec.unit != "cell"; }

std::vector<FitParameter> fit_parameters(const std::vector<std::string>& effects) {
  const auto& registry = EffectRegistry::instance();
  std::vector<FitParameter> out;
  for (const auto& name : registry.names()) {
    const EffectInfo& info = registry.get(name);
    if (!info.baseline) continue;
    for (const auto& spec : info.parameters) out.push_back({name, spec, true});
  }
  for (const auto& name : effects) {
    const EffectInfo& info = registry.get(name);
    if (info.baseline) throw std::invalid_argument("effect \"" + name + "\" is part of the baseline already");
    for (const auto& spec : info.parameters)
      if (is_fitted(spec)) out.push_back({name, spec, false});
  }
  return out;
}

double parameter_value(const ModelParams& params, const FitParameter& p) {
  if (p.surface) {
    SurfaceParameters copy = params.surface;
    const double* field = surface_field(copy, p.spec.name);
    if (!field) throw std::invalid_argument("baseline parameter \"" + p.spec.name + "\" is not a surface field");
    return *field;
  }
  const auto effect = params.effect_parameters.find(p.effect);
  if (effect == params.effect_parameters.end()) return p.spec.default_value;
  const auto value = effect->second.find(p.spec.name);
  return value == effect->second.end() ? p.spec.default_value : value->second;
}

ModelParams with_effects(ModelParams params, const std::vector<std::string>& effects) {
  for (const auto& name : effects) {
    if (std::find(params.effects.begin(), params.effects.end(), name) != params.effects.end()) continue;
    params.effects.push_back(name);
    params.effect_parameters[name] = resolve_parameters(EffectRegistry::instance().get(name), {});
  }
  return params;
}

void set_parameter_value(ModelParams& params, const FitParameter& p, double value) {
  if (p.surface) {
    double* field = surface_field(params.surface, p.spec.name);
    if (!field) throw std::invalid_argument("baseline parameter \"" + p.spec.name + "\" is not a surface field");
    *field = value;
    return;
  }
  params = with_effects(std::move(params), {p.effect});
  params.effect_parameters[p.effect][p.spec.name] = value;
}

std::string parameter_move_note(const FitParameter& p, double from, double to, std::optional<double> ssr_gain) {
  char text[200];
  if (ssr_gain)
    std::snprintf(text, sizeof text, "%s %.6g -> %.6g (sum of squares %+.1f %%)", p.qualified_name().c_str(), from, to,
                  -100.0 * *ssr_gain);
  else
    std::snprintf(text, sizeof text, "%s %.6g -> %.6g (the start does not replay)", p.qualified_name().c_str(), from,
                  to);
  return text;
}

}  // namespace hj
