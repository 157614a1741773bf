#include "fit_command.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>

#include "args.h"
#include "calib/calibration_json.h"
#include "calib/diagnosis.h"
#include "calib/fit_model.h"
#include "calib/report/fit_report_html.h"
#include "calib/report/parameter_lines.h"
#include "calib/report/report_file.h"
#include "calib_args.h"
#include "stage_progress.h"

namespace hj::cli {

namespace {

constexpr const char* kFitUsage =
    "usage: hapticjam fit DATASET --out DIR [--effects a,b] [--holdout NAME,NAME] [--params START]\n"
    "                     [--max-iterations N] [--no-initial] [--profile A,B] [--segments P] [--threads N]\n"
    "Fits the model to the sessions of DATASET: the mass from the levelling pressure, the\n"
    "spring and jammed bending stiffnesses by the paper's Algorithm 1 (bisection), then every\n"
    "parameter (the baseline's and the effects') jointly by bounded least squares (Ceres).\n"
    "Writes DIR/params.json (hapticjam.params/1, loadable by --params; with each parameter's\n"
    "standard error and 95 % interval, r^2, RMSE) and DIR/report.html.\n"
    "  --effects a,b       switch these effects on and fit their parameters too\n"
    "  --holdout A,B       fit without these sessions and report the error on them\n"
    "  --params START      start from these values (default: the paper's)\n"
    "  --max-iterations N  least-squares iterations (default 20)\n"
    "  --no-initial        skip the levelling and Algorithm 1 estimates\n"
    "  --profile A,B       profile-likelihood intervals for these parameters too (loose ones always)\n";

int fit(const CalibArgs& args) {
  const auto start = std::chrono::steady_clock::now();
  const std::clock_t cpu_start = std::clock();
  const Dataset all = read_dataset(args.dataset);
  const Dataset train = select_sessions(all, args.holdout, false);
  const Dataset held = select_sessions(all, args.holdout, true);
  if (train.sessions.empty()) throw std::invalid_argument("--holdout leaves no session to fit");
  const ModelParams start_model = start_params(args, all);
  FitOptions options;
  options.initial_estimates = args.initial_estimates;
  options.least_squares.max_iterations = args.max_iterations;
  options.least_squares.replay = fitting_replay(replay_options(args));
  options.bisection.replay = options.least_squares.replay;
  options.profile_loose = true;
  options.profile_also = args.profile;
  StageProgress progress;
  const FitReport report = fit_model(train, start_model, start_model.effects, options, std::ref(progress));
  const LeastSquaresResult& joint = report.joint;

  const nlohmann::json heldout =
      heldout_json(held, args.holdout, joint.params, options.least_squares.replay,
                   [&](int done, int total, const std::string& name) { progress("held-out sessions", done, total, name); });
  progress.finish();
  const std::vector<std::string> notes = fit_notes(report);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const double cpu_seconds = static_cast<double>(std::clock() - cpu_start) / CLOCKS_PER_SEC;
  nlohmann::json extra = fit_extra_json(all, report, heldout, all.dir.string());
  extra.update({{"seconds", seconds}, {"cpu_seconds", cpu_seconds}, {"timing", progress.timing()}});
  const std::filesystem::path out(args.out);
  write_model_params(out / "params.json", joint.params, extra);

  write_file(out / "report.html", fit_report_html(all.dir.filename().string(), report, heldout));

  std::printf("fit %s (%zu sessions, %ld samples): RMSE %.3f mm, r^2 %.5f\n", all.dir.filename().c_str(),
              train.sessions.size(), joint.residual_count, joint.rmse_mm, joint.r2);
  for (const auto& l : parameter_lines(joint)) std::printf("  %s\n", l.c_str());
  for (const auto& n : notes) std::printf("note: %s\n", n.c_str());
  if (heldout.contains("rmse_mm")) std::printf("held-out RMSE %.3f mm\n", heldout["rmse_mm"].get<double>());
  std::printf("wrote %s in %.1f s (CPU %.1f s)\n", (out / "params.json").c_str(), seconds, cpu_seconds);
  return 0;
}

}  // namespace

int run_fit(const std::vector<std::string>& args) {
  return run_subcommand<CalibArgs>(
      "fit", kFitUsage, args,
      [](const std::vector<std::string>& a) {
        return parse_calib_args(a, {"--params", "--effects", "--holdout", "--max-iterations", "--no-initial", "--profile",
                                    "--segments", "--threads"});
      },
      fit);
}

}  // namespace hj::cli
