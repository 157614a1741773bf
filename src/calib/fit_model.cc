#include "calib/fit_model.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>

namespace hj {

namespace {

const FitParameter* find_parameter(const std::vector<FitParameter>& parameters, const std::string& name) {
  for (const auto& p : parameters)
    if (p.surface && p.spec.name == name) return &p;
  return nullptr;
}

// The levelling estimate from a coarse pressure sweep is only within a few
// per cent, and the jammed captures taken at the levelling pressure depend
// on the mass steeply (the level state is where the net turns from sag to
// dome). So before the jammed bending stiffness, the mass and spring
// stiffness are refined together by least squares on the bare (unjammed,
// unpinned) captures, where the surface depends on them smoothly.
void refine_on_bare_captures(const Dataset& dataset, const std::vector<FitParameter>& parameters,
                             const FitOptions& options, const FitProgress& progress, FitReport& out) {
  const Dataset bare =
      sessions_up_to(dataset, [](const MeasuredCapture& c) { return c.jammed_count() == 0 && c.pinned.empty(); });
  std::vector<FitParameter> surface;
  for (const auto& p : parameters)
    if (p.spec.name == "mass_kg" || p.spec.name == "spring_k") surface.push_back(p);
  if (bare.sessions.empty() || surface.empty()) return;
  try {
    const LeastSquaresResult r =
        fit_least_squares(bare, out.initial, surface, options.least_squares,
                          least_squares_progress(progress, "least squares on the bare captures"));
    out.initial = r.params;
    out.bare_rmse_mm = r.rmse_mm;
  } catch (const SettleInterrupted&) {
    throw;  // the caller stopped the work: not a failed replay
  } catch (const std::exception&) {
    // Keep the estimates so far; the joint fit starts from them.
  }
}

}  // namespace

std::string rmse_detail(double rmse_mm) {
  char detail[64];
  std::snprintf(detail, sizeof detail, "RMSE %.3f mm", rmse_mm);
  return detail;
}

LeastSquaresProgress least_squares_progress(const FitProgress& progress, const std::string& stage) {
  return [progress, stage](int iteration, int max_iterations, double rmse_mm) {
    if (progress) progress(stage, iteration, max_iterations, rmse_detail(rmse_mm));
  };
}

std::optional<double> rmse_of_detail(const std::string& detail) {
  double rmse = 0.0;
  char unit[4] = {};
  if (std::sscanf(detail.c_str(), "RMSE %lf %3s", &rmse, unit) == 2 && std::string(unit) == "mm") return rmse;
  return std::nullopt;
}

LeastSquaresResult probe_and_refit(const Dataset& dataset, const std::vector<FitParameter>& parameters,
                                   const FitOptions& options, const FitProgress& progress, LeastSquaresResult fit,
                                   std::vector<std::string>& notes) {
  // A fit cut off by its iteration cap is probed too: one that crawls along a
  // curved valley (a jammed stiffness walking back from where the baseline
  // had put it, 1.2 towards 4.2, a few per cent of the way an iteration)
  // gets a point far down the valley from the probe and a fresh trust region.
  for (int round = 0; round < options.probe_rounds && (fit.converged || fit.stopped_at_cap); ++round) {
    if (progress) progress("probing the optimum", 0, 1, "");
    const OptimumProbe probe = probe_optimum(dataset, fit, options.least_squares.replay, options.probe);
    if (progress) progress("probing the optimum", 1, 1, probe.moved ? probe.note : "no better point");
    if (!probe.moved) break;
    const std::string stage = "least squares from the probe";
    LeastSquaresResult next = fit_least_squares(dataset, probe.best, parameters, options.least_squares,
                                                least_squares_progress(progress, stage));
    if (!(next.sum_sq_mm2 < fit.sum_sq_mm2)) break;
    char text[320];
    std::snprintf(text, sizeof text, "the least squares %s and was restarted from %s: RMSE %.4f -> %.4f mm",
                  fit.converged ? "converged beside a better basin" : "stopped at its iteration cap short of a better point",
                  probe.note.c_str(), fit.rmse_mm, next.rmse_mm);
    notes.push_back(text);
    fit = std::move(next);
  }
  return fit;
}

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
      if (std::string(name) == "kappa_jam") refine_on_bare_captures(dataset, parameters, options, progress, out);
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
                                least_squares_progress(progress, "least squares"));
  out.joint = probe_and_refit(dataset, parameters, options, progress, std::move(out.joint), out.probe_notes);
  if (options.profile_loose)
    profile_loose_parameters(dataset, parameters, options.least_squares, options.profile, out.joint,
                             [&](const std::string& name, int evaluations, const std::string& detail) {
                               // The number of refits is not known beforehand; about 8 per end.
                               if (progress) progress("profile likelihood: " + name, evaluations, std::max(evaluations, 16), detail);
                             },
                             options.profile_also);
  return out;
}

}  // namespace hj
