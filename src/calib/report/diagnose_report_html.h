// report.html of a diagnosis, for people: the verdict, where the baseline's
// residual concentrates, the error ladder (RMSE as each chosen effect is
// added, down to the noise floor) as an SVG plot, the candidates on the
// baseline and in later rounds, and the baseline's parameters. Shared by
// `hapticjam diagnose` and CalibrationService.Diagnose.
#pragma once

#include <optional>
#include <string>

#include "calib/diagnosis.h"

namespace hj {

// How long the diagnosis took, for the page's last line. The CPU time is
// given where it measures this diagnosis alone (the CLI's process); the
// server runs other calls in the same process and gives none.
struct DiagnoseRunTime {
  double wall_s = 0.0;
  std::optional<double> cpu_s;
};

// A candidate's last column: significant, or why it was not refitted; and
// where the scan started it, if not at the registry defaults.
std::string candidate_note(const CandidateFit& c);

// "The data need: a, b." or that no effect is needed (the page's verdict).
std::string verdict_sentence(const Diagnosis& diagnosis);
// "RMSE 1.043 mm against a noise floor of 1.041 mm (chi-square ... p = 0.2)".
std::string fit_quality_sentence(const Diagnosis& diagnosis);

// @param dataset_name  shown in the title
// @param options       the diagnosis's options (the page states its significance thresholds)
std::string diagnose_report_html(const std::string& dataset_name, const Diagnosis& diagnosis,
                                 const DiagnoseOptions& options, const DiagnoseRunTime& run_time);

}  // namespace hj
