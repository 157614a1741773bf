#include "calib/report/parameter_lines.h"

#include <cstdio>

namespace hj {

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

}  // namespace hj
