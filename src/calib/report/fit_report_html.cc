#include "calib/report/fit_report_html.h"

#include <cstdio>
#include <vector>

#include "calib/calibration_json.h"
#include "calib/report/html_report.h"

namespace hj {

namespace {

std::string num(double v) { return format_number(v, "%.5g"); }

}  // namespace

std::string fit_report_html(const std::string& dataset_name, const FitReport& report, const nlohmann::json& heldout) {
  const LeastSquaresResult& joint = report.joint;
  HtmlReport html("hapticjam fit: " + dataset_name);
  char line[512];
  if (report.levelling.found) {
    std::snprintf(line, sizeof line,
                  "Levelling: the centre crosses the level at %.1f Pa (between %.0f and %.0f Pa in %s), so M = P A / g "
                  "= %.4f kg (95 %%: %.4f .. %.4f kg, from the crossing's profile over %d captures, scatter %.2f mm).",
                  report.levelling.pressure_pa, report.levelling.below_pa, report.levelling.above_pa,
                  report.levelling.session.c_str(), report.levelling.mass_kg, report.levelling.mass_low_kg,
                  report.levelling.mass_high_kg, report.levelling.points, report.levelling.scatter_mm);
    html.paragraph(line);
  } else {
    html.paragraph("Levelling: no unjammed session crosses the level; the mass starts from the given value.");
  }
  for (const auto& s : report.stiffnesses) {
    std::snprintf(line, sizeof line, "Algorithm 1 (bisection) for %s over %d captures: %.5g%s.", s.parameter.c_str(),
                  s.result.captures, s.result.value, s.result.bracketed ? "" : " (not bracketed; start value kept)");
    html.paragraph(line);
  }
  std::snprintf(line, sizeof line, "Joint bounded least squares (%d iterations): RMSE %.3f mm, r^2 = %.5f over %ld samples.",
                joint.iterations, joint.rmse_mm, joint.r2, joint.residual_count);
  html.paragraph(line);
  std::vector<std::vector<std::string>> rows;
  for (const auto& e : joint.estimates)
    rows.push_back({e.parameter.qualified_name(), num(e.value), e.parameter.spec.unit, e.active ? num(e.std_error) : "-",
                    e.active ? num(e.ci95_low) + " .. " + num(e.ci95_high) + " (" + e.interval_method + ")"
                             : "not estimated (no effect)",
                    e.loose ? "loose" : ""});
  html.table({"parameter", "value", "unit", "std. error", "95 % interval", ""}, rows);
  for (const auto& n : fit_notes(report)) html.paragraph(n);
  if (heldout.contains("rmse_mm")) html.paragraph("Held-out sessions: RMSE " + heldout["rmse_mm"].dump() + " mm.");
  return html.html();
}

}  // namespace hj
