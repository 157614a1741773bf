#include "diagnose_command.h"

#include <chrono>
#include <cstdio>
#include <ctime>

#include "args.h"
#include "calib/calibration_json.h"
#include "calib/diagnosis.h"
#include "calib/report/diagnose_report_html.h"
#include "calib/report/report_file.h"
#include "calib_args.h"
#include "stage_progress.h"

namespace hj::cli {

namespace {

constexpr const char* kDiagnoseUsage =
    "usage: hapticjam diagnose DATASET --out DIR [--effects a,b] [--params START] [--max-iterations N]\n"
    "                          [--segments P] [--threads N] [--no-screening]\n"
    "Which physical effect is the model missing? Fits the baseline, then refits with each\n"
    "candidate effect of the registry added, judging each by its leave-one-session-out error\n"
    "and BIC; adds effects greedily while one still helps. Writes DIR/diagnosis.json and\n"
    "DIR/report.html (with the error ladder).\n"
    "  --effects a,b   candidates to try (default: every optional effect in the registry)\n"
    "  --params START  baseline values to start from (default: the paper's)\n"
    "  --no-screening  refit every candidate (default: only those whose predicted gain, from one\n"
    "                  Gauss-Newton step at the current optimum, could pass; see README)\n";

// The stages grouped as the speed report asks: the baseline fit (levelling,
// Algorithm 1, least squares), screening, candidate refits, cross-validation
// (baseline and candidates), the residual pattern; and the like-with-like
// rechecks (calib/like_with_like.h).
nlohmann::json time_split(const nlohmann::json& timing) {
  auto part_of = [](const std::string& stage) -> std::string {
    if (stage.rfind("recheck ", 0) == 0 || stage.find("(refitted from ") != std::string::npos) return "rechecks";
    if (stage.rfind("screening ", 0) == 0 || stage.rfind("scan ", 0) == 0) return "screening";
    if (stage.rfind("candidate ", 0) == 0 || stage.rfind("multi-start ", 0) == 0 ||
        stage.rfind("converging baseline + ", 0) == 0)
      return "refits";
    if (stage == "cross-validation" || stage == "residual pattern") return stage;
    return "baseline fit";
  };
  nlohmann::json out = nlohmann::json::object();
  for (const char* part : {"baseline fit", "cross-validation", "residual pattern", "screening", "refits", "rechecks"})
    out[part] = {{"wall_s", 0.0}, {"cpu_s", 0.0}, {"replays", 0L}};
  for (const auto& t : timing) {
    nlohmann::json& part = out[part_of(t["stage"].get<std::string>())];
    part["wall_s"] = part["wall_s"].get<double>() + t["wall_s"].get<double>();
    part["cpu_s"] = part["cpu_s"].get<double>() + t["cpu_s"].get<double>();
    part["replays"] = part["replays"].get<long>() + t.value("replays", 0L);
  }
  return out;
}

// " (N cold, X s CPU; M failed, Y s CPU)": a cold replay (no warm start) costs
// several warm ones, and a replay with no equilibrium many good ones.
std::string replay_detail_text(const ReplayTally::Entry& e) {
  char text[120];
  std::snprintf(text, sizeof text, " (%ld cold, %.1f s CPU", e.cold, e.cold_cpu_s);
  std::string out = text;
  if (e.failed > 0) {
    std::snprintf(text, sizeof text, "; %ld failed, %.1f s CPU", e.failed, e.failed_cpu_s);
    out += text;
  }
  return out + ")";
}

nlohmann::json replays_json(const ReplayTally& tally) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& e : tally.entries())
    out.push_back({{"session", e.session}, {"replays", e.replays}, {"failed", e.failed}, {"cpu_s", e.cpu_s},
                   {"failed_cpu_s", e.failed_cpu_s}, {"cold", e.cold}, {"cold_cpu_s", e.cold_cpu_s},
                   {"cpu_s_per_replay", e.replays ? e.cpu_s / e.replays : 0.0}});
  return out;
}

int diagnose_dataset(const CalibArgs& args) {
  const auto start = std::chrono::steady_clock::now();
  const std::clock_t cpu_start = std::clock();
  const Dataset dataset = read_dataset(args.dataset);
  CalibArgs base_args = args;
  base_args.effects.clear();
  const ModelParams start_model = start_params(base_args, dataset);
  DiagnoseOptions options;
  options.candidates = args.effects;
  options.screening = args.screening;
  options.fit.least_squares.max_iterations = args.max_iterations;
  options.fit.least_squares.replay = fitting_replay(replay_options(args));
  ReplayTally tally;
  options.fit.least_squares.replay.tally = &tally;
  options.fit.bisection.replay = options.fit.least_squares.replay;
  StageProgress progress(&tally);
  const Diagnosis d = diagnose(dataset, start_model, options, std::ref(progress));
  progress.finish();
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const double cpu_seconds = static_cast<double>(std::clock() - cpu_start) / CLOCKS_PER_SEC;

  const LeastSquaresResult& base = d.baseline.joint;
  nlohmann::json doc = diagnosis_json(d);
  doc.update({{"seconds", seconds},
              {"cpu_seconds", cpu_seconds},
              {"timing", progress.timing()},
              {"time_split", time_split(progress.timing())},
              {"replays", replays_json(tally)}});
  const std::filesystem::path out(args.out);
  write_json(out / "diagnosis.json", doc);
  write_model_params(out / "params.json", d.final_params, {{"verdict", d.verdict}});

  const std::string verdict_text = verdict_sentence(d);
  write_file(out / "report.html", diagnose_report_html(dataset.dir.filename().string(), d, options,
                                                       DiagnoseRunTime{seconds, cpu_seconds}));

  std::printf("diagnose %s: baseline RMSE %.3f mm (held out %.3f), noise floor %.3f mm\n",
              dataset.dir.filename().c_str(), base.rmse_mm, d.baseline_heldout_rmse_mm, d.noise_floor_mm);
  for (const auto& c : d.ranking)
    std::printf("  %-20s RMSE %.3f  held out %.3f  dBIC %10.1f %s\n", c.added.c_str(), c.fit.rmse_mm,
                c.heldout_rmse_mm, c.delta_bic,
                candidate_note(c).c_str());
  for (const auto& f : d.pattern.findings) std::printf("%s\n", f.c_str());
  for (const auto& n : d.notes) std::printf("note: %s\n", n.c_str());
  for (const auto& t : progress.timing())
    std::printf("  time in %-40s %7.1f s wall %7.1f s CPU %5ld replays\n", t["stage"].get<std::string>().c_str(),
                t["wall_s"].get<double>(), t["cpu_s"].get<double>(), t["replays"].get<long>());
  for (const auto& [part, t] : doc["time_split"].items())
    std::printf("  %-20s %7.1f s wall %7.1f s CPU %5ld replays\n", part.c_str(), t["wall_s"].get<double>(),
                t["cpu_s"].get<double>(), t["replays"].get<long>());
  for (const auto& e : tally.entries())
    std::printf("  replays of %-20s %5ld x %6.3f s CPU = %7.1f s%s\n", e.session.c_str(), e.replays,
                e.replays ? e.cpu_s / e.replays : 0.0, e.cpu_s,
                replay_detail_text(e).c_str());
  std::printf("final model: %s; %s\n", fit_quality_sentence(d).c_str(),
              d.goodness.explained ? "consistent with the sensor's noise" : "NOT explained by the sensor's noise");
  std::printf("%s\nwrote %s in %.1f s (CPU %.1f s)\n", verdict_text.c_str(), (out / "diagnosis.json").c_str(), seconds,
              cpu_seconds);
  return 0;
}

}  // namespace

int run_diagnose(const std::vector<std::string>& args) {
  return run_subcommand<CalibArgs>(
      "diagnose", kDiagnoseUsage, args,
      [](const std::vector<std::string>& a) {
        return parse_calib_args(a, {"--params", "--effects", "--max-iterations", "--segments", "--threads", "--no-screening"});
      },
      diagnose_dataset);
}

}  // namespace hj::cli
