// What `compare` writes, built from one evaluation, so the CLI and the
// server (CalibrationService.Compare) hand out the same documents:
// summary.json, a residual heat map per capture and a self-contained
// report.html (the heat maps embedded, plots as inline SVG).
#pragma once

#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "calib/dataset.h"
#include "calib/model_params.h"
#include "calib/residuals.h"

namespace hj {

struct ReportFile {
  std::string path;   // relative to the output folder, e.g. "maps/mixed-1/003.png"
  std::string bytes;
};

struct CompareReport {
  nlohmann::json summary;        // summary.json, each capture naming its heat map ("image")
  std::string html;              // report.html
  std::vector<ReportFile> maps;  // one PNG per capture
};

// @param scale_mm  the heat maps' colour scale, +-scale_mm
// @param progress  (done, total, map path) after each heat map
CompareReport compare_report(const Dataset& dataset, const ModelParams& params, const Evaluation& evaluation,
                             double scale_mm,
                             const std::function<void(int, int, const std::string&)>& progress = {});

}  // namespace hj
