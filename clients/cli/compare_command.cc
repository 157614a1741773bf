#include "compare_command.h"

#include <chrono>
#include <cstdio>
#include <iostream>

#include "args.h"
#include "calib/diagnosis.h"
#include "calib_args.h"
#include "calib/report/compare_report.h"
#include "progress.h"
#include "calib/report/report_file.h"

namespace hj::cli {

namespace {

constexpr const char* kCompareUsage =
    "usage: hapticjam compare DATASET --out DIR [--params FILE] [--effects a,b] [--scale-mm MM]\n"
    "                         [--segments P] [--threads N]\n"
    "Replays every session of DATASET (a folder of session folders) with the model and\n"
    "compares each capture with its measured frame. Writes DIR/summary.json (RMSE, mean\n"
    "absolute and largest error per capture, per cell), a residual heat map per capture\n"
    "(DIR/maps/SESSION/NNN.png) and DIR/report.html (self-contained: the maps embedded).\n"
    "  --params FILE   model parameters (hapticjam.params/1, e.g. from 'fit'); default: the paper's\n"
    "  --effects a,b   switch these effects on (registry defaults unless FILE sets them)\n"
    "  --scale-mm MM   the heat maps' colour scale, +-MM (default 5)\n";

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
  ProgressLine images("heat maps");
  const CompareReport report = compare_report(dataset, params, evaluation, args.scale_mm,
                                              [&](int done, int total, const std::string& path) {
                                                images.update(done, total, path);
                                              });
  images.finish();
  const std::filesystem::path out(args.out);
  for (const ReportFile& map : report.maps) write_file(out / map.path, map.bytes);
  write_json(out / "summary.json", report.summary);
  write_file(out / "report.html", report.html);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("%s: %zu sessions, %d captures: RMSE %.3f mm, MAE %.3f mm (noise floor %.3f mm); %s/summary.json, "
              "%s/report.html in %.1f s\n",
              dataset.dir.filename().c_str(), dataset.sessions.size(), dataset.capture_count(), evaluation.rmse_mm(),
              evaluation.mae_mm(), noise_floor_mm(dataset), out.c_str(), out.c_str(), seconds);
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
