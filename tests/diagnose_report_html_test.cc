// The diagnose page from a diagnosis made by hand (no fitting): the verdict
// in words, the error ladder as one SVG with a point per rung for the fitted
// and the held-out RMSE, a candidate row per ranked effect with its figures,
// the screening's note for a candidate not refitted, the later rounds, the
// baseline's parameters, and the run time as the caller measured it.
#include <gtest/gtest.h>

#include "calib/fit_parameters.h"
#include "calib/report/diagnose_report_html.h"

namespace hj {
namespace {

size_t count(const std::string& text, const std::string& part) {
  size_t n = 0;
  for (size_t at = text.find(part); at != std::string::npos; at = text.find(part, at + part.size())) ++n;
  return n;
}

CandidateFit candidate(const std::string& added, double rmse, double heldout, double delta_bic) {
  CandidateFit c;
  c.effects = {added};
  c.added = added;
  c.fit.rmse_mm = rmse;
  c.heldout_rmse_mm = heldout;
  c.delta_bic = delta_bic;
  return c;
}

// demo-bending's shape: bending chosen, area_pressure screened out, a third
// candidate refitted without gain; stiffening tried on top of bending.
Diagnosis bending_found() {
  Diagnosis d;
  d.noise_floor_mm = 1.04;
  d.baseline.joint.rmse_mm = 2.5;
  d.baseline_heldout_rmse_mm = 2.75;
  ParameterEstimate k;
  k.parameter = fit_parameters({})[0];
  k.value = 58.0;
  k.std_error = 0.5;
  k.ci95_low = 57.02;
  k.ci95_high = 58.98;
  d.baseline.joint.estimates = {k};
  d.ranking = {candidate("bending", 1.06, 1.1, -812.4), candidate("area_pressure", 2.4, 2.7, -3.0),
               candidate("stiffening", 2.49, 2.76, 4.2)};
  d.ranking[0].significant = true;
  d.ranking[1].screened_out = true;
  d.ranking[1].screening_note = "predicted held-out gain 0.4 % < 0.5 %";
  d.later_rounds = {candidate("stiffening", 1.059, 1.12, 6.1)};
  d.later_rounds[0].effects = {"bending", "stiffening"};
  d.verdict = {"bending"};
  d.goodness = {1.06, 1.04, 6240.0, 6000, 0.015, 0.205, true};
  d.ladder = {{"baseline", 2.5, 2.75}, {"+ bending", 1.06, 1.1}};
  d.pattern.findings = {"The residual concentrates in jammed cells (RMSE 3.1 mm against 1.9 mm elsewhere)."};
  d.pattern.splits = {{"in jammed cells", "elsewhere", 3.1, 1.9, 1200, 4800}};
  return d;
}

TEST(DiagnoseReportHtml, StatesTheVerdictLadderAndEveryCandidate) {
  const Diagnosis d = bending_found();
  const std::string html = diagnose_report_html("demo-bending", d, DiagnoseOptions{}, {12.34, 20.06});
  EXPECT_NE(html.find("<title>hapticjam diagnose: demo-bending</title>"), std::string::npos);
  EXPECT_NE(html.find("<h2>Verdict</h2>\n<p>The data need: bending.</p>"), std::string::npos) << html;
  EXPECT_EQ(verdict_sentence(d), "The data need: bending.");
  // One plot, one marker per rung for each of its two series, the rungs
  // named on the x axis and the noise floor drawn.
  EXPECT_EQ(count(html, "<svg"), 1u);
  EXPECT_EQ(count(html, "<circle"), 2 * d.ladder.size());
  EXPECT_EQ(count(html, "<polyline"), 2u);
  for (const char* part : {">baseline</text>", ">+ bending</text>", ">noise floor 1.04</text>", ">held out (LOSO)</text>"})
    EXPECT_NE(html.find(part), std::string::npos) << part;
  // The baseline row, then a row per ranked candidate with its figures.
  EXPECT_NE(html.find("<tr><td>baseline</td><td>2.500</td><td>2.750</td><td>0</td><td></td></tr>"), std::string::npos);
  EXPECT_NE(html.find("<tr><td>bending</td><td>1.060</td><td>1.100</td><td>-812.4</td><td>significant</td></tr>"),
            std::string::npos);
  EXPECT_NE(html.find("<tr><td>area_pressure</td><td>2.400</td><td>2.700</td><td>-3.0</td><td>screened out "
                      "(predicted): predicted held-out gain 0.4 % &lt; 0.5 %</td></tr>"),
            std::string::npos)
      << html;
  EXPECT_NE(html.find("<tr><td>stiffening</td><td>2.490</td><td>2.760</td><td>4.2</td><td></td></tr>"),
            std::string::npos);
  EXPECT_NE(html.find("<tr><td>bending + stiffening</td><td>1.059</td>"), std::string::npos);
  // Where the residual concentrates, the baseline's parameter, the thresholds and run time.
  EXPECT_NE(html.find("<tr><td>in jammed cells</td><td>3.100</td><td>1200</td><td>elsewhere</td><td>1.900</td>"),
            std::string::npos);
  EXPECT_NE(html.find("<p>The residual concentrates in jammed cells"), std::string::npos);
  EXPECT_NE(html.find("<pre>" + d.baseline.joint.estimates[0].parameter.qualified_name() + " "), std::string::npos);
  EXPECT_NE(html.find("falls by at least 1 %, the in-sample RMSE by at least 0.5 % (or delta BIC &lt; -100) and delta BIC &lt; -10. Run time 12.3 s (CPU 20.1 s).</p>"),
            std::string::npos);
}

TEST(DiagnoseReportHtml, SaysWhenNoEffectIsNeededAndTheServersRunTimeHasNoCpu) {
  Diagnosis d = bending_found();
  d.verdict.clear();
  d.ladder.resize(1);
  d.later_rounds.clear();
  d.ranking[0].significant = false;
  const std::string html = diagnose_report_html("demo-baseline", d, DiagnoseOptions{}, {3.0, std::nullopt});
  EXPECT_NE(html.find("<p>No effect is needed: no candidate lowers the held-out error"), std::string::npos);
  EXPECT_EQ(html.find("The data need"), std::string::npos);
  EXPECT_EQ(count(html, "<circle"), 2u);
  EXPECT_EQ(html.find("Later rounds"), std::string::npos);
  EXPECT_NE(html.find("Run time 3.0 s.</p>"), std::string::npos);
  EXPECT_EQ(html.find("CPU"), std::string::npos);
}

// A baseline well above the floor is never "no effect is needed": the
// verdict says how far above, how low the best candidate got, and where
// the residual is.
TEST(DiagnoseReportHtml, SaysTheModelDoesNotExplainTheDataAboveTheFloor) {
  Diagnosis d = bending_found();
  d.verdict.clear();
  d.ranking[0].significant = false;
  d.goodness = {2.5, 1.04, 34670.0, 6000, 0.0, 2.27, false};
  d.best_rmse_mm = 2.4;
  d.best_effects = {"area_pressure"};
  d.final_pattern.worst_cells = {{1, 2}, {0, 2}};
  d.final_pattern.worst_cell_rmse_mm = {3.1, 1.5};
  d.final_pattern.splits = {{"near the clamped edge", "inside", 1.0, 2.9, 100, 200}};
  EXPECT_EQ(verdict_sentence(d),
            "The model does not explain the data: RMSE 2.500 mm against a floor of 1.040 mm; the best candidates "
            "lower it to 2.400 mm (area_pressure); the residual concentrates in cells [1, 2] (3.10 mm), [0, 2] "
            "(1.50 mm).");
  const std::string html = diagnose_report_html("bump", d, DiagnoseOptions{}, {3.0, std::nullopt});
  EXPECT_EQ(html.find("No effect is needed"), std::string::npos);
  EXPECT_NE(html.find("not the sensor's noise alone"), std::string::npos);
  d.verdict = {"bending"};
  EXPECT_EQ(verdict_sentence(d).rfind("The data need at least: bending; but the model does not explain the data", 0),
            0u)
      << verdict_sentence(d);
}

}  // namespace
}  // namespace hj
