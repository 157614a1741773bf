#include "calib/stiffness_bisection.h"

#include <cmath>
#include <exception>

namespace hj {

namespace {

// Mean over the chosen captures of (mean |predicted| - mean |measured|).
double excess_deflection_mm(const Dataset& dataset, const Evaluation& evaluation, const CaptureFilter& filter) {
  double sum = 0.0;
  int n = 0;
  for (size_t s = 0; s < dataset.sessions.size(); ++s)
    for (size_t c = 0; c < dataset.sessions[s].captures.size(); ++c) {
      const MeasuredCapture& measured = dataset.sessions[s].captures[c];
      if (!filter(measured)) continue;
      const Eigen::MatrixXd& residual = evaluation.sessions[s].captures[c].residual_mm;
      double predicted_abs = 0.0, measured_abs = 0.0;
      int count = 0;
      for (int iy = 0; iy < residual.rows(); ++iy)
        for (int ix = 0; ix < residual.cols(); ++ix) {
          if (std::isnan(residual(iy, ix))) continue;
          const double m = measured.heights_mm(iy, ix);
          predicted_abs += std::abs(m + residual(iy, ix));
          measured_abs += std::abs(m);
          ++count;
        }
      if (count == 0) continue;
      sum += (predicted_abs - measured_abs) / count;
      ++n;
    }
  return n ? sum / n : 0.0;
}

}  // namespace

BisectionResult fit_stiffness_by_bisection(const Dataset& dataset, const ModelParams& start,
                                           const FitParameter& parameter, const CaptureFilter& filter,
                                           const BisectionOptions& options, const BisectionProgress& progress) {
  BisectionResult out;
  out.value = parameter_value(start, parameter);
  // Only the sessions with a chosen capture need replaying, each up to its
  // last chosen capture.
  const Dataset used = sessions_up_to(dataset, filter);
  for (const auto& s : dataset.sessions)
    for (const auto& c : s.captures) out.captures += filter(c) ? 1 : 0;
  if (used.sessions.empty() || out.value <= 0.0) return out;
  constexpr int kMaxGrowth = 4;
  const int total = 2 + 2 * kMaxGrowth + options.iterations;
  // NaN where the model finds no equilibrium at that value. Each replay
  // starts its settles from the previous evaluation's settled states.
  std::vector<ReplayTrace> last_traces;
  auto excess = [&](double value) {
    ModelParams params = start;
    set_parameter_value(params, parameter, value);
    double e = std::nan("");
    try {
      std::vector<ReplayTrace> traces;
      e = excess_deflection_mm(used, evaluate_dataset(used, params, options.replay, {}, &last_traces, &traces), filter);
      last_traces = std::move(traces);
    } catch (const SettleInterrupted&) {
      throw;  // the caller stopped the work: not a failed replay
    } catch (const std::exception&) {
    }
    ++out.evaluations;
    if (progress) progress(out.evaluations, total);
    return e;
  };
  // Bracket: stiffer -> less deflection, so excess(lo) > 0 > excess(hi).
  // An end where the model fails moves back toward the start value.
  const double v0 = out.value;
  const double floor = std::max(parameter.spec.lower, v0 * 1e-3);
  double lo = std::max(floor, v0 / 2.0), hi = std::min(parameter.spec.upper, v0 * 2.0);
  double e_lo = excess(lo), e_hi = excess(hi);
  for (int i = 0; i < kMaxGrowth; ++i) {
    if (std::isnan(e_lo)) e_lo = excess(lo = std::sqrt(lo * v0));
    else if (e_lo < 0.0 && lo > floor) e_lo = excess(lo = std::max(floor, lo / 4.0));
    if (std::isnan(e_hi)) e_hi = excess(hi = std::sqrt(hi * v0));
    else if (e_hi > 0.0 && hi < parameter.spec.upper) e_hi = excess(hi = std::min(parameter.spec.upper, hi * 4.0));
  }
  if (!(e_lo >= 0.0 && e_hi <= 0.0)) return out;
  out.bracketed = true;
  for (int i = 0; i < options.iterations; ++i) {
    const double mid = std::sqrt(lo * hi);
    const double e = excess(mid);
    if (std::isnan(e)) break;  // keep the bracket found so far
    (e > 0.0 ? lo : hi) = mid;
  }
  out.value = std::sqrt(lo * hi);
  if (progress) progress(total, total);
  return out;
}

}  // namespace hj
