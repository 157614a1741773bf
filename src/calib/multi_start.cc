#include "calib/multi_start.h"

#include <cmath>
#include <limits>

#include "calib/residuals.h"

namespace hj {

std::vector<double> range_starts(const ParameterSpec& spec, int starts) {
  std::vector<double> out;
  if (starts < 1) return out;
  if (starts == 1) return {spec.upper};
  for (int k = 0; k < starts; ++k) {
    const double t = static_cast<double>(k) / (starts - 1);
    if (spec.lower == 0.0 && spec.upper > 0.0)
      out.push_back(spec.upper * std::pow(10.0, -(starts - 1 - k)));
    else if (spec.lower > 0.0)
      out.push_back(spec.lower * std::pow(spec.upper / spec.lower, t));
    else
      out.push_back(spec.lower + t * (spec.upper - spec.lower));
  }
  return out;
}

bool wants_multi_start(const std::string& effect) {
  const EffectInfo& info = EffectRegistry::instance().get(effect);
  if (info.measurement_only) return false;
  for (const auto& spec : info.parameters)
    if (is_fitted(spec)) return true;
  return false;
}

MultiStart multi_start(const Dataset& dataset, const ModelParams& start, const std::vector<FitParameter>& parameters,
                       const std::string& effect, const LeastSquaresOptions& fit, const MultiStartOptions& options) {
  MultiStart out;
  LeastSquaresOptions short_fit = start_fit_options(fit, options.iterations);
  // A start is only a start: one that only the simulator's fallbacks could
  // settle is skipped, as the scan's points are, and fails in a fraction of
  // the time (a failed replay with them cost 20-40 good ones).
  short_fit.replay.fallbacks = false;
  out.best_sum_sq_mm2 = std::numeric_limits<double>::infinity();
  for (const auto& parameter : parameters) {
    if (parameter.surface || parameter.effect != effect) continue;
    out.parameter += (out.parameter.empty() ? "" : ",") + parameter.qualified_name();
    for (double value : range_starts(parameter.spec, options.starts)) {
      ModelParams from = start;
      set_parameter_value(from, parameter, value);
      StartTried tried{parameter.qualified_name(), value, std::numeric_limits<double>::quiet_NaN(), value};
      try {
        const LeastSquaresResult r = fit_least_squares(dataset, from, parameters, short_fit);
        tried.rmse_mm = r.rmse_mm;
        tried.fitted = parameter_value(r.params, parameter);
        if (r.sum_sq_mm2 < out.best_sum_sq_mm2) {
          out.best_sum_sq_mm2 = r.sum_sq_mm2;
          out.best = r.params;
          out.found = true;
        }
      } catch (const SettleInterrupted&) {
        throw;  // the caller stopped the work: not a failed replay
      } catch (const std::exception&) {
        // No equilibrium from this start: it stays NaN.
      }
      out.tried.push_back(tried);
    }
  }
  return out;
}

}  // namespace hj
