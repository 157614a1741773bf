#include "calib/report/compare_report.h"

#include <cstdio>
#include <filesystem>

#include "calib/calibration_json.h"
#include "calib/diagnosis.h"
#include "calib/report/html_report.h"
#include "calib/report/residual_image.h"

namespace hj {

namespace {

std::string number(double v, const char* format = "%.3f") { return format_number(v, format); }

// Per-cell RMSE as table rows, row 0 at the bottom (+y up, as the maps).
std::vector<std::vector<std::string>> cell_rows(const Eigen::MatrixXd& cells) {
  std::vector<std::vector<std::string>> rows;
  for (int r = static_cast<int>(cells.rows()) - 1; r >= 0; --r) {
    std::vector<std::string> row{"row " + std::to_string(r)};
    for (int c = 0; c < cells.cols(); ++c) row.push_back(number(cells(r, c), "%.2f"));
    rows.push_back(row);
  }
  return rows;
}

}  // namespace

CompareReport compare_report(const Dataset& dataset, const ModelParams& params, const Evaluation& evaluation,
                             double scale_mm, const std::function<void(int, int, const std::string&)>& progress) {
  CompareReport out;
  out.summary = compare_summary_json(dataset, params, evaluation);
  const double floor = noise_floor_mm(dataset);
  HtmlReport report("hapticjam compare: " + dataset.dir.filename().string());
  report.paragraph("Model: " + model_params_json(params).dump());
  report.paragraph("Over all " + std::to_string(evaluation.samples) + " compared samples: RMSE " +
                   number(evaluation.rmse_mm()) + " mm, mean absolute " + number(evaluation.mae_mm()) +
                   " mm. Noise floor of the sensor (a perfect model): " + number(floor) + " mm.");
  std::vector<std::vector<std::string>> rows;
  Plot pressure_plot{"Error against pressure", "pressure (kPa)", "RMSE (mm)", {}, {}, 0.0, floor, "noise floor", {}};
  PlotSeries unjammed{"unjammed", {}, {}, "#1f77b4", false, true}, jammed{"some cells jammed", {}, {}, "#d62728", false, true};
  HtmlReport figures("");
  const int total_maps = dataset.capture_count();
  for (size_t s = 0; s < dataset.sessions.size(); ++s) {
    const MeasuredSession& measured = dataset.sessions[s];
    for (size_t c = 0; c < measured.captures.size(); ++c) {
      const MeasuredCapture& capture = measured.captures[c];
      const CaptureError& e = evaluation.sessions[s].captures[c];
      const std::string stem = std::filesystem::path(capture.frame).stem().string();
      const std::string path = "maps/" + measured.session.name + "/" + stem + ".png";
      const std::string title = measured.session.name + " " + capture.frame + " " + capture.label + " (" +
                                number(capture.pressure_pa / 1000.0, "%.3g") + " kPa): RMSE " +
                                number(e.rmse_mm(), "%.2f") + " mm";
      out.maps.push_back({path, residual_png(measured.session, e.residual_mm, scale_mm, capture.pinned, title)});
      figures.embedded_png(out.maps.back().bytes, title, 420);
      if (progress) progress(static_cast<int>(out.maps.size()), total_maps, path);
      out.summary["sessions"][s]["captures"][c]["image"] = path;
      rows.push_back({measured.session.name, capture.frame, capture.label, number(capture.pressure_pa / 1000.0),
                      std::to_string(capture.jammed_count()), number(e.rmse_mm()), number(e.mae_mm()),
                      number(e.max_mm), number(100.0 * e.share_within_accuracy(), "%.1f %%")});
      PlotSeries& series = capture.jammed_count() ? jammed : unjammed;
      series.x.push_back(capture.pressure_pa / 1000.0);
      series.y.push_back(e.rmse_mm());
    }
  }
  const Eigen::MatrixXd cells = evaluation.cell_rmse_mm();
  std::vector<std::string> cell_header{""};
  for (int c = 0; c < cells.cols(); ++c) cell_header.push_back("col " + std::to_string(c));
  report.heading("Residual per cell (RMSE, mm; row 0 at the bottom, +y up)");
  report.table(cell_header, cell_rows(cells));
  report.heading("Error against pressure");
  pressure_plot.series = {unjammed, jammed};
  report.raw(svg_plot(pressure_plot));
  report.heading("Captures");
  report.table({"session", "frame", "label", "kPa", "jammed", "RMSE mm", "MAE mm", "max mm", "within accuracy"}, rows);
  report.heading("Residual heat maps (predicted - measured, fixed scale +-" + number(scale_mm, "%.1f") +
                 " mm; black circles: nodes, filled: pinned; grey: not compared)");
  report.raw(figures.body());
  out.html = report.html();
  return out;
}

}  // namespace hj
