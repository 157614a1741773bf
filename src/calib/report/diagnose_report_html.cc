#include "calib/report/diagnose_report_html.h"

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

std::string verdict_sentence(const Diagnosis& d) {
  if (d.verdict.empty())
    return "No effect is needed: no candidate lowers the held-out error by a real margin with a better BIC; the "
           "baseline explains the data.";
  std::string s = "The data need: ";
  for (size_t k = 0; k < d.verdict.size(); ++k) s += (k ? ", " : "") + d.verdict[k];
  return s + ".";
}

std::string diagnose_report_html(const std::string& dataset_name, const Diagnosis& d, const DiagnoseOptions& options,
                                 const DiagnoseRunTime& run_time) {
  const LeastSquaresResult& base = d.baseline.joint;
  HtmlReport html("hapticjam diagnose: " + dataset_name);
  html.heading("Verdict");
  html.paragraph(verdict_sentence(d));
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
                 num(100 * options.min_fit_gain, "%.1f") + " % and delta BIC < " +
                 num(options.max_delta_bic, "%.0f") + ". Run time " + num(run_time.wall_s, "%.1f") + " s" +
                 (run_time.cpu_s ? " (CPU " + num(*run_time.cpu_s, "%.1f") + " s)" : "") + ".");
  return html.html();
}

}  // namespace hj
