#include "calib/report/diagnose_report_html.h"

#include <algorithm>
#include <cstdio>
#include <vector>

#include "calib/calibration_json.h"
#include "calib/report/html_report.h"
#include "calib/report/parameter_lines.h"

namespace hj {

namespace {

std::string num(double v, const char* format = "%.3f") { return format_number(v, format); }

}  // namespace

std::string candidate_note(const CandidateFit& c) {
  std::string note = c.significant ? "significant" : c.screened_out ? "screened out (predicted): " + c.screening_note : "";
  if (!c.scan_note.empty()) note += (note.empty() ? "" : "; ") + std::string("started at ") + c.scan_note;
  if (!c.recheck_note.empty()) note += (note.empty() ? "" : "; ") + c.recheck_note;
  if (!c.probe_note.empty()) note += (note.empty() ? "" : "; ") + c.probe_note;
  return note;
}

namespace {

std::vector<std::string> candidate_row(const std::string& name, const CandidateFit& c) {
  return {name, num(c.fit.rmse_mm), num(c.heldout_rmse_mm), num(c.delta_bic, "%.1f"), candidate_note(c)};
}

// Fitted and held-out RMSE over the ladder's rungs, with the noise floor.
std::string ladder_svg(const Diagnosis& d) {
  Plot plot{"Error as each chosen effect is added", "model", "RMSE (mm)", {}, {}, 0.0, d.noise_floor_mm,
            "noise floor " + num(d.noise_floor_mm, "%.2f"), {}};
  PlotSeries fitted{"fitted", {}, {}, "#1f77b4"}, heldout{"held out (LOSO)", {}, {}, "#d62728"};
  for (size_t k = 0; k < d.ladder.size(); ++k) {
    plot.x_ticks.push_back(d.ladder[k].label);
    fitted.x.push_back(static_cast<double>(k));
    fitted.y.push_back(d.ladder[k].rmse_mm);
    heldout.x.push_back(static_cast<double>(k));
    heldout.y.push_back(d.ladder[k].heldout_rmse_mm);
  }
  plot.series = {fitted, heldout};
  return svg_plot(plot);
}

}  // namespace

namespace {

std::string joined(const std::vector<std::string>& names, const char* separator = ", ") {
  std::string s;
  for (size_t k = 0; k < names.size(); ++k) s += (k ? separator : "") + names[k];
  return s;
}

// "cells [1, 2] (2.31 mm), [0, 2] (1.52 mm); larger near the clamped edge
// (1.61 mm) than inside (1.20 mm)".
std::string residual_location(const ResidualPattern& p) {
  std::string s;
  char part[200];
  for (size_t k = 0; k < p.worst_cells.size(); ++k) {
    std::snprintf(part, sizeof part, "%s[%d, %d] (%.2f mm)", k ? ", " : "cells ", p.worst_cells[k].first,
                  p.worst_cells[k].second, p.worst_cell_rmse_mm[k]);
    s += part;
  }
  for (const auto& split : p.splits) {
    if (split.samples == 0 || split.other_samples == 0 || !(split.rmse_mm >= 1.25 * split.other_rmse_mm)) continue;
    std::snprintf(part, sizeof part, "; larger %s (%.2f mm) than %s (%.2f mm)", split.name.c_str(), split.rmse_mm,
                  split.other.c_str(), split.other_rmse_mm);
    s += part;
  }
  return s.empty() ? "no cell in particular" : s;
}

// The chosen effects, a local one with its place and size in words:
// "cell_defect (cell [1, 2] at 0.50 times the others' spring stiffness)".
std::string effects_in_words(const std::vector<std::string>& effects, const ModelParams& params) {
  std::vector<std::string> out;
  for (const auto& e : effects) {
    const auto values = params.effect_parameters.find(e);
    if (values == params.effect_parameters.end() || !values->second.count("row") || !values->second.count("col") ||
        !values->second.count("factor")) {
      out.push_back(e);
      continue;
    }
    const double factor = values->second.at("factor");
    char text[200];
    std::snprintf(text, sizeof text, "%s (cell [%.0f, %.0f] at %.2f times the others' spring stiffness: %s)",
                  e.c_str(), values->second.at("row"), values->second.at("col"), factor,
                  factor < 1.0 ? "softer" : "stiffer");
    out.push_back(text);
  }
  return joined(out);
}

}  // namespace

std::string fit_quality_sentence(const Diagnosis& d) {
  const GoodnessOfFit& g = d.goodness;
  char s[300];
  std::snprintf(s, sizeof s,
                "RMSE %.3f mm against a noise floor of %.3f mm (chi-square %.4g on %ld degrees of freedom, p = %.3g)",
                g.rmse_mm, g.noise_floor_mm, g.chi2, g.dof, g.p_value);
  return s;
}

std::string verdict_sentence(const Diagnosis& d) {
  if (!d.goodness.explained) {
    char s[400];
    std::string text =
        d.verdict.empty() ? "" : "The data need at least: " + effects_in_words(d.verdict, d.final_params) + "; but ";
    std::snprintf(s, sizeof s, "%s model does not explain the data: RMSE %.3f mm against a floor of %.3f mm",
                  text.empty() ? "The" : "the", d.goodness.rmse_mm, d.goodness.noise_floor_mm);
    text += s;
    if (d.best_rmse_mm < d.goodness.rmse_mm - 1e-9 || !d.verdict.empty()) {
      std::snprintf(s, sizeof s, "; the best candidates lower it to %.3f mm (%s)",
                    std::min(d.best_rmse_mm, d.goodness.rmse_mm), joined(d.best_effects, " + ").c_str());
      text += s;
    } else {
      text += "; no candidate lowers it";
    }
    return text + "; the residual concentrates in " + residual_location(d.final_pattern) + ".";
  }
  if (d.verdict.empty())
    return "No effect is needed: no candidate lowers the held-out error by a real margin with a better BIC; the "
           "baseline explains the data.";
  return "The data need: " + effects_in_words(d.verdict, d.final_params) + ".";
}

std::string diagnose_report_html(const std::string& dataset_name, const Diagnosis& d, const DiagnoseOptions& options,
                                 const DiagnoseRunTime& run_time) {
  const LeastSquaresResult& base = d.baseline.joint;
  HtmlReport html("hapticjam diagnose: " + dataset_name);
  html.heading("Verdict");
  html.paragraph(verdict_sentence(d));
  html.paragraph("Goodness of fit of the final model: " + fit_quality_sentence(d) + "; " +
                 (d.goodness.explained ? "consistent with the sensor's noise." : "not the sensor's noise alone."));
  for (const auto& n : d.notes) html.paragraph("Note: " + n);
  for (const auto& s : d.skipped) html.paragraph("Not fitted: " + s);
  html.heading("Where the baseline's residual concentrates");
  for (const auto& f : d.pattern.findings) html.paragraph(f);
  std::vector<std::vector<std::string>> split_rows;
  for (const auto& s : d.pattern.splits)
    split_rows.push_back({s.name, num(s.rmse_mm), std::to_string(s.samples), s.other, num(s.other_rmse_mm),
                          std::to_string(s.other_samples)});
  html.table({"region", "RMSE mm", "samples", "rest", "RMSE mm", "samples"}, split_rows);
  html.heading("Error ladder");
  html.raw(ladder_svg(d));
  html.heading("Candidates on the baseline (best first)");
  std::vector<std::vector<std::string>> rows;
  rows.push_back({"baseline", num(base.rmse_mm), num(d.baseline_heldout_rmse_mm), "0", ""});
  for (const auto& c : d.ranking) rows.push_back(candidate_row(c.added, c));
  html.table({"effect", "RMSE mm", "held-out RMSE mm", "delta BIC", ""}, rows);
  if (!d.later_rounds.empty()) {
    html.heading("Later rounds (on top of the chosen effects)");
    rows.clear();
    for (const auto& c : d.later_rounds) {
      std::string on;
      for (const auto& e : c.effects) on += (on.empty() ? "" : " + ") + e;
      rows.push_back(candidate_row(on, c));
    }
    html.table({"effects", "RMSE mm", "held-out RMSE mm", "delta BIC", ""}, rows);
  }
  html.heading("Baseline parameters");
  for (const auto& l : parameter_lines(base)) html.raw("<pre>" + html_escape(l) + "</pre>");
  for (const auto& n : loose_notes(base)) html.paragraph(n);
  html.paragraph("Significant = the leave-one-session-out RMSE falls by at least " +
                 num(100 * options.min_heldout_gain, "%.0f") + " %, the in-sample RMSE by at least " +
                 num(100 * options.min_fit_gain, "%.1f") + " % (or delta BIC < " +
                 num(options.strong_delta_bic, "%.0f") + ") and delta BIC < " +
                 num(options.max_delta_bic, "%.0f") + ". Run time " + num(run_time.wall_s, "%.1f") + " s" +
                 (run_time.cpu_s ? " (CPU " + num(*run_time.cpu_s, "%.1f") + " s)" : "") + ".");
  return html.html();
}

}  // namespace hj
