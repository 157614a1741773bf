#include "calib/fit_model.h"

#include <cstdio>

namespace hj {

namespace {

const FitParameter* find_parameter(const std::vector<FitParameter>& parameters, const std::string& name) {
  for (const auto& p : parameters)
    if (p.surface && p.spec.name == name) return &p;
  return nullptr;
}

}  // namespace

FitReport fit_model(const Dataset& dataset, const ModelParams& start, const std::vector<std::string>& effects,
                    const FitOptions& options, const FitProgress& progress) {
  FitReport out;
  out.start = with_effects(start, effects);
  out.initial = out.start;
  const std::vector<FitParameter> parameters = fit_parameters(out.initial.effects);
  if (options.initial_estimates) {
    out.levelling = levelling_mass(dataset, out.initial.surface.gravity);
    if (progress) progress("levelling", 1, 1, out.levelling.found ? "zero crossing found" : "no zero crossing");
    if (out.levelling.found) {
      const FitParameter* mass = find_parameter(parameters, "mass_kg");
      if (mass && out.levelling.mass_kg >= mass->spec.lower && out.levelling.mass_kg <= mass->spec.upper)
        out.initial.surface.mass_kg = out.levelling.mass_kg;
    }
    // Algorithm 1: the spring stiffness on the bare (unjammed, unpinned)
    // captures, then the jammed bending stiffness on the jammed, unpinned.
    const std::pair<const char*, CaptureFilter> stiffnesses[] = {
        {"spring_k", [](const MeasuredCapture& c) { return c.jammed_count() == 0 && c.pinned.empty(); }},
        {"kappa_jam", [](const MeasuredCapture& c) { return c.jammed_count() > 0 && c.pinned.empty(); }},
    };
    for (const auto& [name, filter] : stiffnesses) {
      const FitParameter* p = find_parameter(parameters, name);
      if (!p) continue;
      const std::string stage = std::string("algorithm 1: ") + name;
      BisectionResult r = fit_stiffness_by_bisection(dataset, out.initial, *p, filter, options.bisection,
                                                     [&](int done, int total) {
                                                       if (progress) progress(stage, done, total, "");
                                                     });
      if (r.bracketed) set_parameter_value(out.initial, *p, r.value);
      out.stiffnesses.push_back({name, r});
    }
  }
  out.joint = fit_least_squares(dataset, out.initial, parameters, options.least_squares,
                                [&](int iteration, int max_iterations, double rmse) {
                                  char detail[64];
                                  std::snprintf(detail, sizeof detail, "RMSE %.3f mm", rmse);
                                  if (progress) progress("least squares", iteration, max_iterations, detail);
                                });
  return out;
}

}  // namespace hj
