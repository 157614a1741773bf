#include "compare_command.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>

#include "args.h"
#include "calib/calibration_json.h"
#include "calib/diagnosis.h"
#include "calib_args.h"
#include "html_report.h"
#include "progress.h"
#include "residual_image.h"

namespace hj::cli {

namespace {

constexpr const char* kCompareUsage =
    "usage: hapticjam compare DATASET --out DIR [--params FILE] [--effects a,b] [--scale-mm MM]\n"
    "                         [--segments P] [--threads N]\n"
    "Replays every session of DATASET (a folder of session folders) with the model and\n"
    "compares each capture with its measured frame. Writes DIR/summary.json (RMSE, mean\n"
    "absolute and largest error per capture, per cell), a residual heat map per capture\n"
    "(DIR/maps/SESSION/NNN.png) and DIR/report.html.\n"
    "  --params FILE   model parameters (hapticjam.params/1, e.g. from 'fit'); default: the paper's\n"
    "  --effects a,b   switch these effects on (registry defaults unless FILE sets them)\n"
    "  --scale-mm MM   the heat maps' colour scale, +-MM (default 5)\n";

std::string number(double v, const char* format = "%.3f") {
  char buf[32];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

int compare(const CalibArgs& args) {
  const auto start = std::chrono::steady_clock::now();
  const Dataset dataset = read_dataset(args.dataset);
  const ModelParams params = start_params(args, dataset);
  ProgressLine progress("compare " + dataset.dir.filename().string());
  const Evaluation evaluation = evaluate_dataset(dataset, params, replay_options(args),
                                                 [&](int done, int total, const std::string& name) {
                                                   progress.update(done, total, name);
                                                 });
  progress.finish();
  const std::filesystem::path out(args.out);
  const double floor = noise_floor_mm(dataset);

  nlohmann::json summary = compare_summary_json(dataset, params, evaluation);
  HtmlReport report("hapticjam compare: " + dataset.dir.filename().string());
  report.paragraph("Model: " + model_params_json(params).dump());
  report.paragraph("Over all " + std::to_string(evaluation.samples) + " compared samples: RMSE " +
                   number(evaluation.rmse_mm()) + " mm, mean absolute " + number(evaluation.mae_mm()) +
                   " mm. Noise floor of the sensor (a perfect model): " + number(floor) + " mm.");
  std::vector<std::vector<std::string>> rows;
  Plot pressure_plot{"Error against pressure", "pressure (kPa)", "RMSE (mm)", {}, {}, 0.0, floor, "noise floor", {}};
  PlotSeries unjammed{"unjammed", {}, {}, "#1f77b4", false, true}, jammed{"some cells jammed", {}, {}, "#d62728", false, true};
  ProgressLine images("heat maps");
  const int total_images = dataset.capture_count();
  int done_images = 0;
  std::string figures;
  for (size_t s = 0; s < dataset.sessions.size(); ++s) {
    const MeasuredSession& measured = dataset.sessions[s];
    for (size_t c = 0; c < measured.captures.size(); ++c) {
      const MeasuredCapture& capture = measured.captures[c];
      const CaptureError& e = evaluation.sessions[s].captures[c];
      const std::string stem = std::filesystem::path(capture.frame).stem().string();
      const std::string image = "maps/" + measured.session.name + "/" + stem + ".png";
      const std::string title = measured.session.name + " " + capture.frame + " " + capture.label + " (" +
                                number(capture.pressure_pa / 1000.0, "%.3g") + " kPa): RMSE " + number(e.rmse_mm(), "%.2f") + " mm";
      write_residual_png(out / image, measured.session, e.residual_mm, args.scale_mm, capture.pinned, title);
      images.update(++done_images, total_images, image);
      summary["sessions"][s]["captures"][c]["image"] = image;
      rows.push_back({measured.session.name, capture.frame, capture.label, number(capture.pressure_pa / 1000.0),
                      std::to_string(capture.jammed_count()), number(e.rmse_mm()), number(e.mae_mm()),
                      number(e.max_mm), number(100.0 * e.share_within_accuracy(), "%.1f %%")});
      (capture.jammed_count() ? jammed : unjammed).x.push_back(capture.pressure_pa / 1000.0);
      (capture.jammed_count() ? jammed : unjammed).y.push_back(e.rmse_mm());
      figures += "<figure><img src='" + html_escape(image) + "' width='420'><figcaption>" + html_escape(title) +
                 "</figcaption></figure>\n";
    }
  }
  images.finish();
  const Eigen::MatrixXd cells = evaluation.cell_rmse_mm();
  std::vector<std::vector<std::string>> cell_rows;
  for (int r = static_cast<int>(cells.rows()) - 1; r >= 0; --r) {
    std::vector<std::string> row{"row " + std::to_string(r)};
    for (int c = 0; c < cells.cols(); ++c) row.push_back(number(cells(r, c), "%.2f"));
    cell_rows.push_back(row);
  }
  write_json(out / "summary.json", summary);

  std::vector<std::string> cell_header{""};
  for (int c = 0; c < cells.cols(); ++c) cell_header.push_back("col " + std::to_string(c));
  report.heading("Residual per cell (RMSE, mm; row 0 at the bottom, +y up)");
  report.table(cell_header, cell_rows);
  report.heading("Error against pressure");
  pressure_plot.series = {unjammed, jammed};
  report.raw(svg_plot(pressure_plot));
  report.heading("Captures");
  report.table({"session", "frame", "label", "kPa", "jammed", "RMSE mm", "MAE mm", "max mm", "within accuracy"}, rows);
  report.heading("Residual heat maps (predicted - measured, fixed scale +-" + number(args.scale_mm, "%.1f") +
                 " mm; black circles: nodes, filled: pinned; grey: not compared)");
  report.raw(figures);
  report.write(out / "report.html");
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("%s: %zu sessions, %d captures: RMSE %.3f mm, MAE %.3f mm (noise floor %.3f mm); %s/summary.json, "
              "%s/report.html in %.1f s\n",
              dataset.dir.filename().c_str(), dataset.sessions.size(), dataset.capture_count(), evaluation.rmse_mm(),
              evaluation.mae_mm(), floor, out.c_str(), out.c_str(), seconds);
  return 0;
}

}  // namespace

int run_compare(const std::vector<std::string>& args) {
  return run_subcommand<CalibArgs>(
      "compare", kCompareUsage, args,
      [](const std::vector<std::string>& a) {
        return parse_calib_args(a, {"--params", "--effects", "--scale-mm", "--segments", "--threads"});
      },
      compare);
}

}  // namespace hj::cli
