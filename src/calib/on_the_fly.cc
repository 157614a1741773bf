#include "calib/on_the_fly.h"

#include <algorithm>
#include <cstdio>
#include <map>
#include <stdexcept>

#include "calib/diagnosis.h"
#include "calib/effect_scan.h"
#include "sim/settle_report.h"

namespace hj {

namespace {

bool contains(const std::vector<std::string>& names, const std::string& name) {
  return std::find(names.begin(), names.end(), name) != names.end();
}

LeastSquaresResult fit(const Dataset& dataset, const ModelParams& start, const OnTheFlyOptions& options,
                       int max_iterations, int& replays) {
  LeastSquaresOptions ls;
  ls.max_iterations = max_iterations;
  ls.replay = fitting_replay(options.replay);
  LeastSquaresResult out = fit_least_squares(dataset, start, on_the_fly_parameters(start, options), ls);
  replays += out.evaluations + out.jacobians * out.free_parameters;
  return out;
}

std::string judged(const std::string& effect, const LeastSquaresResult& trial, const LeastSquaresResult& current,
                   bool significant) {
  char text[240];
  std::snprintf(text, sizeof text, "%s: RMSE %.3f -> %.3f mm, delta BIC %.1f: %s", effect.c_str(), current.rmse_mm,
                trial.rmse_mm, bic(trial) - bic(current), significant ? "significant" : "not significant");
  return text;
}

// The candidate on top of `current`: its start scanned coarsely
// (effect_scan.h, as diagnose does: a fit from the neutral value can stop
// far from the data), then every parameter refitted briefly.
LeastSquaresResult try_candidate(const Dataset& dataset, const LeastSquaresResult& current, const std::string& effect,
                                 const OnTheFlyOptions& options, int& replays) {
  const ModelParams start = with_effects(current.params, {effect});
  EffectScanOptions coarse;
  coarse.fractions = options.scan_fractions;
  const EffectScan scan =
      scan_effect_start(dataset, start, on_the_fly_parameters(start, options), effect, options.replay, coarse);
  replays += scan.replays;
  return fit(dataset, scan.best, options, options.trial_iterations, replays);
}

// Every significant candidate added at once, fitted jointly (one fit
// rather than diagnose's greedy rounds, each of which refits every
// remaining candidate), to max_iterations: a trial's few iterations stop
// short of its optimum. It starts from the best trial, whole (its baseline
// parameters moved with its effect: a stiffening trial softens spring_k),
// with the other trials' effects added at their values; if it ends worse
// than that trial, the trial alone is kept.
LeastSquaresResult joint_fit(const Dataset& dataset, std::vector<LeastSquaresResult>& trials, OnTheFlyFit& out,
                             const OnTheFlyOptions& options) {
  const auto best = std::min_element(trials.begin(), trials.end(), [](const auto& a, const auto& b) {
    return a.rmse_mm < b.rmse_mm;
  });
  const std::string best_effect = out.added[size_t(best - trials.begin())];
  ModelParams joint = best->params;
  for (size_t k = 0; k < trials.size(); ++k) {
    if (trials.begin() + long(k) == best) continue;
    joint = with_effects(joint, {out.added[k]});
    joint.effect_parameters[out.added[k]] = trials[k].params.effect_parameters.at(out.added[k]);
  }
  LeastSquaresResult fitted = fit(dataset, joint, options, options.max_iterations, out.replays);
  if (fitted.rmse_mm <= best->rmse_mm) return fitted;
  char text[200];
  std::snprintf(text, sizeof text, "joint fit: RMSE %.3f mm, above %s's alone (%.3f mm): %s alone kept",
                fitted.rmse_mm, best_effect.c_str(), best->rmse_mm, best_effect.c_str());
  out.notes.push_back(text);
  out.added = {best_effect};
  return std::move(*best);
}

}  // namespace

MeasuredSession captured_session(const std::string& name, const SessionDevice& device, const SessionGrid& grid,
                                 const std::vector<Action>& actions, const std::vector<RunCapture>& captures) {
  Session session;
  session.name = name;
  session.device = device;
  session.grid = grid;
  std::map<int, const Eigen::MatrixXd*> frames;  // by step index
  size_t done = 0;
  const auto add_action = [&](const Action& a) {
    SessionStep step;
    step.action = a;
    step.index = static_cast<int>(session.steps.size());
    session.steps.push_back(step);
  };
  for (const RunCapture& c : captures) {
    if (c.frame_mm.rows() != grid.ny || c.frame_mm.cols() != grid.nx)
      throw std::invalid_argument("run " + name + ": a frame of " + std::to_string(c.frame_mm.rows()) + " x " +
                                  std::to_string(c.frame_mm.cols()) + " samples for a grid of " +
                                  std::to_string(grid.ny) + " x " + std::to_string(grid.nx));
    if (c.after_actions < done || c.after_actions > actions.size())
      throw std::invalid_argument("run " + name + ": a capture after " + std::to_string(c.after_actions) +
                                  " actions, out of order or past its " + std::to_string(actions.size()));
    for (; done < c.after_actions; ++done) add_action(actions[done]);
    SessionStep capture;
    capture.kind = SessionStep::Kind::kCapture;
    capture.frame = captures.size() == 1 ? name : name + " capture " + std::to_string(frames.size() + 1);
    capture.index = static_cast<int>(session.steps.size());
    session.steps.push_back(capture);
    frames[capture.index] = &c.frame_mm;
  }
  return measured_session(std::move(session),
                          [&](const Session&, const SessionStep& step) { return *frames.at(step.index); });
}

MeasuredSession run_session(const std::string& name, const SessionDevice& device, const SessionGrid& grid,
                            const std::vector<Action>& actions, const Eigen::MatrixXd& frame_mm) {
  return captured_session(name, device, grid, actions, {{actions.size(), frame_mm}});
}

void OnTheFlyOptions::validate() const {
  if (max_iterations < 1) throw std::invalid_argument("on-the-fly calibration: max_iterations must be >= 1");
  if (trial_iterations < 1) throw std::invalid_argument("on-the-fly calibration: trial_iterations must be >= 1");
  for (double f : scan_fractions)
    if (!(f > 0.0 && f <= 1.0))
      throw std::invalid_argument("on-the-fly calibration: scan_fractions must lie in (0, 1]");
  if (!(min_fit_gain >= 0.0 && min_fit_gain < 1.0))
    throw std::invalid_argument("on-the-fly calibration: min_fit_gain must be in [0, 1)");
  if (!(max_delta_bic <= 0.0)) throw std::invalid_argument("on-the-fly calibration: max_delta_bic must be <= 0");
  for (const auto& name : candidates)
    if (EffectRegistry::instance().get(name).baseline)
      throw std::invalid_argument("on-the-fly calibration: candidate \"" + name + "\" is part of the baseline");
}

std::vector<FitParameter> on_the_fly_parameters(const ModelParams& params, const OnTheFlyOptions& options) {
  std::vector<std::string> fitted_effects;
  for (const auto& e : params.effects)
    if (contains(options.candidates, e)) fitted_effects.push_back(e);
  std::vector<FitParameter> out;
  for (const FitParameter& p : fit_parameters(fitted_effects))
    if ((!p.surface || contains(options.surface_parameters, p.spec.name)) &&
        !contains(options.held, p.qualified_name()))
      out.push_back(p);
  for (const auto& name : options.surface_parameters)
    if (std::none_of(out.begin(), out.end(), [&](const FitParameter& p) { return p.surface && p.spec.name == name; }))
      throw std::invalid_argument("on-the-fly calibration: \"" + name + "\" is not a baseline parameter");
  return out;
}

OnTheFlyFit calibrate_on_the_fly(const Dataset& dataset, const ModelParams& start, const OnTheFlyOptions& options) {
  options.validate();
  OnTheFlyFit out;
  LeastSquaresResult current = fit(dataset, start, options, options.max_iterations, out.replays);
  // Each candidate not yet in the model, alone on top of it (a short fit).
  std::vector<LeastSquaresResult> significant;  // the trials of out.added, in order
  for (const auto& effect : options.candidates) {
    if (contains(current.params.effects, effect)) continue;
    try {
      LeastSquaresResult trial = try_candidate(dataset, current, effect, options, out.replays);
      const bool passes = bic(trial) - bic(current) < options.max_delta_bic &&
                          trial.rmse_mm <= (1.0 - options.min_fit_gain) * current.rmse_mm;
      out.notes.push_back(judged(effect, trial, current, passes));
      if (!passes) continue;
      out.added.push_back(effect);
      significant.push_back(std::move(trial));
    } catch (const SettleInterrupted&) {
      throw;
    } catch (const std::exception& e) {
      out.notes.push_back(effect + ": not fitted (" + e.what() + ")");
    }
  }
  if (!significant.empty()) current = joint_fit(dataset, significant, out, options);
  for (const auto& e : out.added) out.notes.push_back("added " + e);
  out.params = current.params;
  out.estimates = current.estimates;
  out.rmse_mm = current.rmse_mm;
  out.samples = current.residual_count;
  out.captures = dataset.capture_count();
  return out;
}

}  // namespace hj
