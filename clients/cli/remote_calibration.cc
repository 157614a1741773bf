// remote compare, remote fit, remote diagnose: the CalibrationService. The
// local dataset folder is uploaded (each session's session.json and the
// frames it names); the server's progress is shown as the local commands
// show theirs, and the documents it returns are written into --out.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "calib/report/report_file.h"
#include "calib_args.h"
#include "hapticjam/v1/calibration_service.grpc.pb.h"
#include "remote_command.h"
#include "remote_connection.h"
#include "stage_progress.h"

namespace hj::cli {

namespace v1 = ::hapticjam::v1;
namespace fs = std::filesystem;

namespace {

constexpr const char* kCalibUsage =
    "usage: hapticjam remote compare|fit|diagnose DATASET --out DIR [the local command's options]\n"
    "Uploads DATASET (each session folder's session.json and the frames it names) and runs\n"
    "compare, fit or diagnose on the server, showing its progress. Writes what the server\n"
    "returns: DIR/summary.json, DIR/report.html and the heat maps DIR/maps/ (compare),\n"
    "DIR/params.json and DIR/report.html (fit), DIR/diagnosis.json, DIR/params.json and\n"
    "DIR/report.html (diagnose). Options as the local commands:\n"
    "  --params FILE        model parameters (hapticjam.params/1), sent with the request\n"
    "  --effects a,b        effects switched on (compare, fit) or the candidates (diagnose)\n"
    "  --segments P         mesh segments per cell edge (default 4)\n"
    "  --scale-mm MM        compare only: the heat maps' colour scale, +-MM (default 5)\n"
    "  --threads N          threads on the server for this call (default: its cores)\n"
    "  --max-iterations N   least-squares iterations (fit, diagnose; default 20)\n"
    "  --holdout A,B        fit only: sessions left out and reported as held out\n"
    "  --no-initial         fit only: skip the levelling and Algorithm 1 estimates\n"
    "  --profile A,B        fit only: profile-likelihood intervals for these parameters too\n"
    "  --no-screening       diagnose only: refit every candidate\n";

struct RemoteCalibArgs {
  RemoteOptions remote;
  std::string command;  // compare, fit, diagnose
  CalibArgs calib;      // the local command's options, sent with the request
};

// The options each command takes, beside the remote ones and --out.
const std::set<std::string>& allowed_options(const std::string& command) {
  static const std::set<std::string> compare = {"--params", "--effects", "--segments", "--threads", "--scale-mm"};
  static const std::set<std::string> fit = {"--params",  "--effects", "--segments", "--threads", "--max-iterations",
                                            "--holdout", "--no-initial", "--profile"};
  static const std::set<std::string> diagnose = {"--params",         "--effects", "--segments", "--threads",
                                                 "--max-iterations", "--no-screening"};
  return command == "compare" ? compare : command == "fit" ? fit : diagnose;
}

RemoteCalibArgs parse_calib(const std::string& command, const std::vector<std::string>& args) {
  RemoteCalibArgs out;
  out.command = command;
  out.calib = parse_calib_args(
      args, allowed_options(command), [&](ArgCursor& c) { return take_remote_flag(c, out.remote); },
      /*known_effects_only=*/false);
  finish_remote_options(out.remote);
  return out;
}

std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path.string() + ": cannot read");
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// A JSON document as the local commands write it (with a final newline).
void write_text(const fs::path& path, const std::string& text) { write_file(path, text + "\n"); }

// A file name the server sent, to be written under --out: relative and
// without "..", so a server cannot write outside the folder.
fs::path safe_relative_path(const std::string& name) {
  const fs::path path(name);
  bool ok = !name.empty() && path.is_relative();
  for (const auto& part : path) ok = ok && part != "..";
  if (!ok) throw std::runtime_error("the server sent a file named \"" + name + "\": not a path inside --out");
  return path;
}

// The dataset folder as an upload: every sub-folder holding a session.json,
// with the frame files its steps name. Nothing is validated here (the server
// does, naming the file): a session.json that is not JSON goes as it is, a
// frame that is missing is left out.
v1::UploadedDataset upload_of(const fs::path& dir) {
  if (!fs::is_directory(dir)) throw std::runtime_error(dir.string() + ": not a folder");
  std::vector<fs::path> sessions;
  for (const auto& entry : fs::directory_iterator(dir))
    if (entry.is_directory() && fs::exists(entry.path() / "session.json")) sessions.push_back(entry.path());
  if (sessions.empty()) throw std::runtime_error(dir.string() + ": no session folder (a sub-folder with a session.json)");
  std::sort(sessions.begin(), sessions.end());
  v1::UploadedDataset upload;
  upload.set_name(fs::absolute(dir).lexically_normal().filename().string());
  if (upload.name().empty()) upload.set_name(fs::absolute(dir).lexically_normal().parent_path().filename().string());
  for (const fs::path& session_dir : sessions) {
    v1::UploadedSession* s = upload.add_sessions();
    s->set_name(session_dir.filename().string());
    s->set_session_json(read_text(session_dir / "session.json"));
    const nlohmann::json doc = nlohmann::json::parse(s->session_json(), nullptr, false);
    if (!doc.is_object() || !doc.contains("steps") || !doc["steps"].is_array()) continue;
    std::set<std::string> added;
    for (const auto& step : doc["steps"]) {
      if (!step.is_object() || !step.contains("frame") || !step["frame"].is_string()) continue;
      const std::string frame = step["frame"].get<std::string>();
      if (!added.insert(frame).second || !fs::is_regular_file(session_dir / frame)) continue;
      v1::SessionFile* f = s->add_files();
      f->set_path(frame);
      f->set_content(read_text(session_dir / frame));
    }
  }
  return upload;
}

v1::CalibrationOptions options_of(const CalibArgs& args) {
  v1::CalibrationOptions o;
  if (!args.params_file.empty()) o.set_params_json(read_text(args.params_file));
  for (const auto& e : args.effects) o.add_effects(e);
  o.set_segments(args.segments);
  o.set_threads(args.threads);
  o.set_max_iterations(args.max_iterations);
  o.set_scale_mm(args.scale_mm);
  return o;
}

// Reads the stream, showing progress, until its result; throws CallError
// if the server ends it with an error.
template <class Event>
Event read_events(grpc::ClientReader<Event>& reader, const std::string& call) {
  StageProgress progress;
  Event last;
  bool have_result = false;
  for (Event event; reader.Read(&event);) {
    if (event.has_progress()) {
      const v1::CalibrationProgress& p = event.progress();
      progress(p.stage(), p.done(), p.total(), p.detail());
    } else {
      last = std::move(event);
      have_result = true;
    }
  }
  progress.finish();
  check(reader.Finish(), call);
  if (!have_result) throw std::runtime_error("the server ended the " + call + " stream without a result");
  return last;
}

void print_parameters(const google::protobuf::RepeatedPtrField<v1::FittedParameter>& parameters) {
  for (const auto& p : parameters) {
    if (p.active())
      std::printf("  %-24s %.6g %s (95 %%: %.6g .. %.6g, %s)%s\n", p.name().c_str(), p.value(), p.unit().c_str(),
                  p.ci95_low(), p.ci95_high(), p.interval_method().c_str(), p.loose() ? "  LOOSELY CONSTRAINED" : "");
    else
      std::printf("  %-24s %.6g %s (changes no capture; not estimated)\n", p.name().c_str(), p.value(), p.unit().c_str());
  }
}

int remote_calibration(const RemoteCalibArgs& args) {
  RemoteConnection connection(args.remote);
  auto stub = v1::CalibrationService::NewStub(connection.channel());
  const CalibArgs& calib = args.calib;
  const v1::UploadedDataset dataset = upload_of(calib.dataset);
  const v1::CalibrationOptions options = options_of(calib);
  const fs::path out(calib.out);
  auto context = connection.context(0);  // no deadline unless --timeout: a diagnosis takes minutes
  if (args.command == "compare") {
    v1::CompareRequest request;
    *request.mutable_dataset() = dataset;
    *request.mutable_options() = options;
    auto reader = stub->Compare(context.get(), request);
    const v1::CompareResult r = read_events(*reader, "Compare").result();
    write_text(out / "summary.json", r.summary_json());
    write_file(out / "report.html", r.report_html());
    for (const v1::SessionFile& map : r.maps()) write_file(out / safe_relative_path(map.path()), map.content());
    std::printf("%s: RMSE %.3f mm, MAE %.3f mm over %ld samples (noise floor %.3f mm), %.1f s on the server; %s\n",
                dataset.name().c_str(), r.rmse_mm(), r.mae_mm(), static_cast<long>(r.samples()), r.noise_floor_mm(),
                r.seconds(), (out / "summary.json").c_str());
    std::printf("wrote %s and %d heat maps under %s\n", (out / "report.html").c_str(), r.maps_size(),
                (out / "maps").c_str());
  } else if (args.command == "fit") {
    v1::FitRequest request;
    *request.mutable_dataset() = dataset;
    *request.mutable_options() = options;
    for (const auto& h : calib.holdout) request.add_holdout(h);
    for (const auto& p : calib.profile) request.add_profile(p);
    request.set_no_initial(!calib.initial_estimates);
    auto reader = stub->Fit(context.get(), request);
    const v1::FitResult r = read_events(*reader, "Fit").result();
    write_text(out / "params.json", r.params_json());
    write_file(out / "report.html", r.report_html());
    std::printf("fit %s: RMSE %.3f mm, r^2 %.5f (noise floor %.3f mm), %.1f s on the server\n", dataset.name().c_str(),
                r.rmse_mm(), r.r2(), r.noise_floor_mm(), r.seconds());
    print_parameters(r.parameters());
    if (r.has_heldout_rmse_mm()) std::printf("held-out RMSE %.3f mm\n", r.heldout_rmse_mm());
    std::printf("wrote %s\n", (out / "params.json").c_str());
  } else {
    v1::DiagnoseRequest request;
    *request.mutable_dataset() = dataset;
    *request.mutable_options() = options;
    request.set_no_screening(!calib.screening);
    auto reader = stub->Diagnose(context.get(), request);
    const v1::DiagnoseResult r = read_events(*reader, "Diagnose").result();
    write_text(out / "diagnosis.json", r.diagnosis_json());
    write_text(out / "params.json", r.params_json());
    write_file(out / "report.html", r.report_html());
    std::string verdict;
    for (const auto& e : r.verdict()) verdict += (verdict.empty() ? "" : ", ") + e;
    std::printf("diagnose %s: baseline RMSE %.3f mm (held out %.3f), chosen model %.3f mm (held out %.3f), noise floor "
                "%.3f mm, %.1f s on the server\n%s\nwrote %s, %s, %s\n",
                dataset.name().c_str(), r.baseline_rmse_mm(), r.baseline_heldout_rmse_mm(), r.final_rmse_mm(),
                r.final_heldout_rmse_mm(), r.noise_floor_mm(), r.seconds(),
                verdict.empty() ? "No effect is needed." : ("The data need: " + verdict + ".").c_str(),
                (out / "diagnosis.json").c_str(), (out / "params.json").c_str(),
                (out / "report.html").c_str());
  }
  return 0;
}

int run(const std::string& command, const std::vector<std::string>& args) {
  static const std::string usage = std::string(kCalibUsage) + kRemoteCommonUsage;
  return run_remote_subcommand<RemoteCalibArgs>(
      command, usage.c_str(), args, [&](const std::vector<std::string>& a) { return parse_calib(command, a); },
      remote_calibration);
}

}  // namespace

int run_remote_compare(const std::vector<std::string>& args) { return run("compare", args); }
int run_remote_fit(const std::vector<std::string>& args) { return run("fit", args); }
int run_remote_diagnose(const std::vector<std::string>& args) { return run("diagnose", args); }

}  // namespace hj::cli
