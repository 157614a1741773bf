#include "calib/calibration_json.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace hj {

namespace {

nlohmann::json candidate_json(const CandidateFit& c) {
  nlohmann::json j = {{"effect", c.added},
                      {"effects", c.effects},
                      {"rmse_mm", c.fit.rmse_mm},
                      {"heldout_rmse_mm", c.heldout_rmse_mm},
                      {"delta_bic", c.delta_bic},
                      {"significant", c.significant},
                      {"screened_out", c.screened_out},
                      {"params", model_params_json(c.fit.params)},
                      {"uncertainties", uncertainties_json(c.fit)}};
  if (!c.heldout_session_rmse_mm.empty())
    j["heldout_by_session"] = {{"rmse_mm", c.heldout_session_rmse_mm}, {"fold_step", c.fold_step}};
  if (c.screened_out) j["screening"] = c.screening_note;
  if (!c.scan_note.empty()) j["scan"] = c.scan_note;
  if (!c.recheck_note.empty()) j["recheck"] = c.recheck_note;
  if (!c.probe_note.empty()) j["probe"] = c.probe_note;
  if (!c.starts_tried.empty()) {
    nlohmann::json starts = nlohmann::json::array();
    for (const auto& t : c.starts_tried)
      starts.push_back({{"parameter", t.parameter}, {"start", t.value}, {"fitted", t.fitted}, {"rmse_mm", t.rmse_mm}});
    j["starts"] = {{"parameter", c.multi_start_parameter}, {"tried", starts}};
  }
  if (c.screened)
    j["predicted"] = {{"rmse_mm", c.predicted_rmse_mm},
                      {"heldout_rmse_mm", c.predicted_heldout_rmse_mm},
                      {"delta_bic", c.predicted_delta_bic}};
  return j;
}

}  // namespace

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

std::vector<std::string> fit_notes(const FitReport& report) {
  std::vector<std::string> out = report.probe_notes;
  for (std::string& n : loose_notes(report.joint)) out.push_back(std::move(n));
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

nlohmann::json compare_summary_json(const Dataset& dataset, const ModelParams& params, const Evaluation& evaluation) {
  nlohmann::json summary = {{"rmse_mm", evaluation.rmse_mm()},
                            {"mae_mm", evaluation.mae_mm()},
                            {"samples", evaluation.samples},
                            {"noise_floor_mm", noise_floor_mm(dataset)},
                            {"params", model_params_json(params)},
                            {"sessions", nlohmann::json::array()},
                            {"cells", nlohmann::json::array()}};
  for (size_t s = 0; s < dataset.sessions.size(); ++s) {
    const MeasuredSession& measured = dataset.sessions[s];
    nlohmann::json captures = nlohmann::json::array();
    for (size_t c = 0; c < measured.captures.size(); ++c) {
      const MeasuredCapture& capture = measured.captures[c];
      const CaptureError& e = evaluation.sessions[s].captures[c];
      captures.push_back({{"frame", capture.frame},
                          {"label", capture.label},
                          {"pressure_kpa", capture.pressure_pa / 1000.0},
                          {"jammed_cells", capture.jammed_count()},
                          {"pinned_nodes", capture.pinned.size()},
                          {"rmse_mm", e.rmse_mm()},
                          {"mae_mm", e.mae_mm()},
                          {"max_mm", e.max_mm},
                          {"mean_mm", e.mean_mm},
                          {"within_accuracy", e.share_within_accuracy()},
                          {"samples", e.samples},
                          {"uncovered", e.uncovered}});
    }
    summary["sessions"].push_back({{"name", measured.session.name}, {"captures", captures}});
  }
  const Eigen::MatrixXd cells = evaluation.cell_rmse_mm();
  for (int r = 0; r < cells.rows(); ++r)
    for (int c = 0; c < cells.cols(); ++c)
      summary["cells"].push_back({{"cell", {r, c}}, {"rmse_mm", cells(r, c)}, {"samples", evaluation.cell_samples(r, c)}});
  return summary;
}

nlohmann::json heldout_json(const Dataset& held, const std::vector<std::string>& names, const ModelParams& params,
                            const ReplayOptions& replay,
                            const std::function<void(int, int, const std::string&)>& progress) {
  nlohmann::json out = {{"sessions", names}};
  if (held.sessions.empty()) return out;
  const Evaluation e = evaluate_dataset(held, params, replay, [&](int done, int total, const std::string& name) {
    if (progress) progress(done, total, name);
  });
  out["rmse_mm"] = e.rmse_mm();
  out["mae_mm"] = e.mae_mm();
  return out;
}

nlohmann::json fit_extra_json(const Dataset& all, const FitReport& report, const nlohmann::json& heldout,
                              const std::string& dataset_name) {
  const LeastSquaresResult& joint = report.joint;
  nlohmann::json levelling = {{"found", report.levelling.found}};
  if (report.levelling.found)
    levelling.update({{"pressure_pa", report.levelling.pressure_pa},
                      {"mass_kg", report.levelling.mass_kg},
                      {"session", report.levelling.session},
                      {"between_pa", {report.levelling.below_pa, report.levelling.above_pa}},
                      {"pressure_ci95_pa", {report.levelling.pressure_low_pa, report.levelling.pressure_high_pa}},
                      {"mass_ci95_kg", {report.levelling.mass_low_kg, report.levelling.mass_high_kg}},
                      {"points", report.levelling.points},
                      {"scatter_mm", report.levelling.scatter_mm}});
  nlohmann::json algorithm1 = nlohmann::json::object();
  for (const auto& s : report.stiffnesses)
    algorithm1[s.parameter] = {{"value", s.result.value},
                               {"bracketed", s.result.bracketed},
                               {"captures", s.result.captures},
                               {"evaluations", s.result.evaluations}};
  return {{"rmse_mm", joint.rmse_mm},
          {"r2", joint.r2},
          {"samples", joint.residual_count},
          {"noise_floor_mm", noise_floor_mm(all)},
          {"uncertainties", uncertainties_json(joint)},
          {"notes", fit_notes(report)},
          {"heldout", heldout},
          {"levelling", levelling},
          {"algorithm1", algorithm1},
          {"least_squares", {{"iterations", joint.iterations},
                             {"jacobians", joint.jacobians},
                             {"evaluations", joint.evaluations},
                             {"termination", joint.termination}}},
          {"dataset", dataset_name}};
}

nlohmann::json diagnosis_json(const Diagnosis& d) {
  nlohmann::json ranking = nlohmann::json::array(), later = nlohmann::json::array(), worst = nlohmann::json::array();
  for (const auto& c : d.ranking) ranking.push_back(candidate_json(c));
  for (const auto& c : d.later_rounds) later.push_back(candidate_json(c));
  for (auto [r, c] : d.worst_cells) worst.push_back({r, c});
  nlohmann::json baseline_worst = nlohmann::json::array();
  for (auto [r, c] : d.pattern.worst_cells) baseline_worst.push_back({r, c});
  nlohmann::json final_worst = nlohmann::json::array();
  for (auto [r, c] : d.final_pattern.worst_cells) final_worst.push_back({r, c});
  nlohmann::json ladder = nlohmann::json::array();
  for (const auto& step : d.ladder)
    ladder.push_back({{"model", step.label}, {"rmse_mm", step.rmse_mm}, {"heldout_rmse_mm", step.heldout_rmse_mm}});
  const LeastSquaresResult& base = d.baseline.joint;
  return {{"baseline",
           {{"rmse_mm", base.rmse_mm},
            {"heldout_rmse_mm", d.baseline_heldout_rmse_mm},
            {"r2", base.r2},
            {"params", model_params_json(base.params)},
            {"uncertainties", uncertainties_json(base)}}},
          {"ranking", ranking},
          {"later_rounds", later},
          {"verdict", d.verdict},
          {"worst_cells", worst},
          {"baseline_worst_cells", baseline_worst},
          {"findings", d.pattern.findings},
          {"skipped", d.skipped},
          {"notes", d.notes},
          {"ladder", ladder},
          {"noise_floor_mm", d.noise_floor_mm},
          {"explained", d.goodness.explained},
          {"goodness_of_fit",
           {{"rmse_mm", d.goodness.rmse_mm},
            {"noise_floor_mm", d.goodness.noise_floor_mm},
            {"chi2", d.goodness.chi2},
            {"dof", d.goodness.dof},
            {"p_value", d.goodness.p_value},
            {"systematic_mm", d.goodness.systematic_mm},
            {"explained", d.goodness.explained}}},
          {"chi2", d.goodness.chi2},
          {"dof", d.goodness.dof},
          {"p_value", d.goodness.p_value},
          {"best_rmse_mm", d.best_rmse_mm},
          {"best_effects", d.best_effects},
          {"final_worst_cells", final_worst},
          {"final_findings", d.final_pattern.findings},
          {"final_params", model_params_json(d.final_params)}};
}

}  // namespace hj
