#include "fit_report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace hj::cli {

nlohmann::json uncertainties_json(const LeastSquaresResult& fit) {
  nlohmann::json out = nlohmann::json::object();
  for (const auto& e : fit.estimates) {
    nlohmann::json entry = {{"value", e.value}, {"unit", e.parameter.spec.unit}, {"active", e.active}};
    if (e.active) {
      entry["std_error"] = e.std_error;
      entry["ci95"] = {e.ci95_low, e.ci95_high};
      entry["at_bound"] = e.at_bound;
      entry["loose"] = e.loose;
      entry["interval_method"] = e.interval_method;
      if (e.interval_method != "linearised") {
        entry["ci95_linearised"] = {e.linearised_low, e.linearised_high};
        if (e.low_open || e.high_open) entry["ci95_open"] = {e.low_open, e.high_open};
      }
    }
    out[e.parameter.qualified_name()] = entry;
  }
  return out;
}

std::vector<std::string> parameter_lines(const LeastSquaresResult& fit) {
  std::vector<std::string> out;
  char line[256];
  for (const auto& e : fit.estimates) {
    const std::string name = e.parameter.qualified_name();
    const char* unit = e.parameter.spec.unit.c_str();
    if (!e.active) {
      std::snprintf(line, sizeof line, "%-24s %.6g %s (changes no capture; kept, not estimated)", name.c_str(), e.value,
                    unit);
    } else if (e.interval_method == "linearised") {
      std::snprintf(line, sizeof line, "%-24s %.6g %s +- %.3g (95 %%: %.6g .. %.6g)%s%s", name.c_str(), e.value, unit,
                    1.96 * e.std_error, e.ci95_low, e.ci95_high, e.loose ? "  LOOSELY CONSTRAINED" : "",
                    e.at_bound ? "  at a bound" : "");
    } else {
      // An interval that need not be symmetric: its ends, how it was found,
      // and the linearised one it replaces.
      std::snprintf(line, sizeof line, "%-24s %.6g %s (95 %%: %s%.6g .. %.6g%s by %s; linearised %.6g .. %.6g)%s%s",
                    name.c_str(), e.value, unit, e.low_open ? "<= " : "", e.ci95_low, e.ci95_high,
                    e.high_open ? " (bound)" : "", e.interval_method.c_str(), e.linearised_low, e.linearised_high,
                    e.loose ? "  LOOSELY CONSTRAINED" : "", e.at_bound ? "  at a bound" : "");
    }
    out.push_back(line);
  }
  return out;
}

std::vector<std::string> loose_notes(const LeastSquaresResult& fit) {
  std::vector<std::string> out;
  char line[320];
  for (const auto& e : fit.estimates) {
    if (!e.active || !e.loose) continue;
    std::snprintf(line, sizeof line,
                  "%s is only loosely constrained by these sessions: its 95 %% interval %.4g .. %.4g %s (%s) is %.0f "
                  "%% of its value wide; sessions that load it more would pin it down.",
                  e.parameter.qualified_name().c_str(), e.ci95_low, e.ci95_high, e.parameter.spec.unit.c_str(),
                  e.interval_method.c_str(), 100.0 * (e.ci95_high - e.ci95_low) / std::max(std::abs(e.value), 1e-300));
    out.push_back(line);
  }
  // Which parameter the data pin down least, beside the others, whether or
  // not it passes the loose threshold (a reader compares, a flag does not).
  std::vector<std::pair<double, std::string>> widths;
  for (const auto& e : fit.estimates)
    if (e.active && e.value != 0.0)
      widths.emplace_back(std::max(e.value - e.ci95_low, e.ci95_high - e.value) / std::abs(e.value),
                          e.parameter.qualified_name());
  if (widths.size() >= 2) {
    std::sort(widths.rbegin(), widths.rend());
    std::string others;
    for (std::size_t k = 1; k < widths.size(); ++k) {
      std::snprintf(line, sizeof line, "%s%s %.2g %%", k > 1 ? ", " : "", widths[k].second.c_str(), 100.0 * widths[k].first);
      others += line;
    }
    std::snprintf(line, sizeof line, "%s is the least constrained parameter: 95 %% half-width %.2g %% of its value (%s).",
                  widths[0].second.c_str(), 100.0 * widths[0].first, others.c_str());
    out.push_back(line);
  }
  return out;
}

}  // namespace hj::cli
