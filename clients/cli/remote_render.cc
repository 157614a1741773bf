// remote render: the RenderService. A goal rendered on the server's device
// with the loop closed, a live progress line, one JSON line per iteration.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>

#include "calib/frame_csv.h"
#include "hapticjam/v1/render_service.grpc.pb.h"
#include "progress.h"
#include "remote_command.h"
#include "remote_connection.h"
#include "remote_goal.h"
#include "remote_messages.h"

namespace hj::cli {

namespace v1 = ::hapticjam::v1;
namespace fs = std::filesystem;

namespace {

constexpr const char* kRenderUsage =
    "usage: hapticjam remote render GOAL|--map NAME --rows R --cols C [--iterations N]\n"
    "                               [--heights absolute] [--out DIR] [--json] [options]\n"
    "Renders GOAL on the server's device with the loop closed: plan, run on the device\n"
    "(a job of the device queue), capture, compare with the goal at the mesh points,\n"
    "correct the targets by the error, and again, until the error stops falling or N\n"
    "iterations (docs/render.md). Needs the operator role.\n"
    "  --iterations N        runs at most (default 5, at most 20)\n"
    "  --correction C        both (default): model, then targets; targets (learn the targets\n"
    "                        from the error); model (after the first run, fit the device\n"
    "                        model on a probe of it, the free membrane at four pressures,\n"
    "                        and plan with it; a fitted camera tilt is taken out of the\n"
    "                        captures); or none (the open-loop plan again, a baseline)\n"
    "  --gain G              of the target correction, (0, 2] (default 1.5)\n"
    "  --keep-camera-plane   compare the captures as they come (default: the camera's tilt\n"
    "                        and offset are fitted on the clamped edge in a capture at rest\n"
    "                        before each run, or with the model,\n"
    "                        and taken out)\n"
    "  --name NAME           the device jobs' names (\"NAME iteration I\", default render)\n"
    "  --out DIR             DIR/goal.csv, DIR/result.json and per iteration DIR/iteration-I/\n"
    "                        plan.json, capture.csv, measured.csv, predicted.csv, targets.csv\n"
    "                        (and model.json: the fitted model, with --correction model|both)\n"
    "  --json                one JSON object per iteration, then {\"result\": ...}\n";

struct RemoteRenderArgs {
  RemoteOptions remote;
  GoalArgs goal;
  std::string out, name;
  int iterations = 0;
  double gain = 0.0;
  v1::RenderCorrection correction = v1::RENDER_CORRECTION_UNSPECIFIED;
  bool json = false, keep_camera_plane = false;
};

RemoteRenderArgs parse_render(const std::vector<std::string>& args) {
  RemoteRenderArgs out;
  for (ArgCursor c(args); c.next();) {
    const std::string& a = c.arg();
    if (take_remote_flag(c, out.remote) || out.goal.take(c)) continue;
    if (a == "--out") out.out = c.value();
    else if (a == "--json") out.json = true;
    else if (a == "--iterations") out.iterations = parse_int(a, c.value(), 1, 20);
    else if (a == "--name") out.name = c.value();
    else if (a == "--keep-camera-plane") out.keep_camera_plane = true;
    else if (a == "--gain") {
      out.gain = parse_number(a, c.value());
      if (!(out.gain > 0 && out.gain <= 2)) throw std::invalid_argument("--gain needs a number in (0, 2]");
    } else if (a == "--correction") {
      const std::string& v = c.value();
      if (v == "targets") out.correction = v1::RENDER_CORRECTION_TARGETS;
      else if (v == "none") out.correction = v1::RENDER_CORRECTION_NONE;
      else if (v == "model") out.correction = v1::RENDER_CORRECTION_MODEL;
      else if (v == "both") out.correction = v1::RENDER_CORRECTION_BOTH;
      else throw std::invalid_argument("--correction needs targets, model, both or none, got \"" + v + "\"");
    } else throw std::invalid_argument(a[0] == '-' ? "unknown option " + a : "unexpected argument \"" + a + "\"");
  }
  out.goal.validate();
  finish_remote_options(out.remote);
  return out;
}

nlohmann::json number_or_null(bool has, double value) { return has ? nlohmann::json(value) : nlohmann::json(nullptr); }

Eigen::MatrixXd points(const google::protobuf::RepeatedField<double>& heights, int rows, int cols) {
  return goal_heights(heights, rows, cols);
}

// {"effects": [...], "parameters": {"spring_k": 61.2, ...}, "rmse_mm": ..., ...}; null without a fit.
nlohmann::json model_json(const v1::FittedModel& m) {
  if (m.captures() == 0) return nullptr;
  nlohmann::json parameters = nlohmann::json::object(), errors = nlohmann::json::object();
  for (const auto& p : m.parameters()) {
    parameters[p.name()] = p.value();
    errors[p.name()] = number_or_null(std::isfinite(p.std_error()), p.std_error());
  }
  const auto strings = [](const auto& field) { return std::vector<std::string>(field.begin(), field.end()); };
  return {{"effects", strings(m.effects())},
          {"added", strings(m.added())},
          {"parameters", parameters},
          {"std_errors", errors},
          {"rmse_mm", m.rmse_mm()},
          {"captures", m.captures()},
          {"replays", m.replays()},
          {"probe_job_id", m.probe_job_id()},
          {"probe_pressures_kpa", std::vector<double>(m.probe_pressures_kpa().begin(), m.probe_pressures_kpa().end())},
          {"notes", strings(m.notes())}};
}

void write_iteration(const fs::path& out, const v1::RenderIteration& it) {
  const fs::path dir = out / ("iteration-" + std::to_string(it.iteration()));
  fs::create_directories(dir);
  nlohmann::json plan = nlohmann::json::parse(to_json_line(it.plan()));
  nlohmann::json doc{{"job_id", it.job_id()}, {"steps_run", it.steps_run()}, {"plan", plan}};
  if (!it.refusal().empty()) doc["refusal"] = it.refusal(), doc["refused_job_id"] = it.refused_job_id();
  std::ofstream(dir / "plan.json") << doc.dump(1) << "\n";
  write_frame_csv(dir / "capture.csv", frame_heights(it.capture()));
  if (it.rest_capture().heights_mm_size() > 0) write_frame_csv(dir / "rest.csv", frame_heights(it.rest_capture()));
  write_frame_csv(dir / "measured.csv", points(it.measured_heights_mm(), it.point_rows(), it.point_cols()));
  write_frame_csv(dir / "predicted.csv", points(it.predicted_heights_mm(), it.point_rows(), it.point_cols()));
  write_frame_csv(dir / "targets.csv", points(it.target_heights_mm(), it.point_rows(), it.point_cols()));
  if (it.model().captures() > 0) std::ofstream(dir / "model.json") << model_json(it.model()).dump(1) << "\n";
}

nlohmann::json iteration_line(const v1::RenderIteration& it) {
  return {{"iteration", it.iteration()},
          {"mae_mm", it.error().mae_mm()},
          {"rmse_mm", it.error().rmse_mm()},
          {"correlation", number_or_null(it.error().has_correlation(), it.error().correlation())},
          {"correction", it.correction()},
          {"screening", it.screening().empty() ? nlohmann::json(nullptr) : nlohmann::json(it.screening())},
          {"prediction_mae_mm", it.prediction_error().mae_mm()},
          {"camera_tilt_mrad", {it.camera().tilt_x_mrad(), it.camera().tilt_y_mrad()}},
          {"camera_offset_mm", it.camera().offset_mm()},
          {"camera_source", it.camera().source()},
          {"model", model_json(it.model())},
          {"fitting_seconds", it.fitting_seconds()},
          {"job_id", it.job_id()},
          {"steps_run", it.steps_run()},
          {"refusal", it.refusal().empty() ? nlohmann::json(nullptr) : nlohmann::json(it.refusal())},
          {"planning_seconds", it.planning_seconds()},
          {"device_seconds", it.device_seconds()}};
}

nlohmann::json result_line(const v1::RenderResult& r) {
  return {{"result",
           {{"iterations", r.iterations()},
            {"mae_mm", r.error().mae_mm()},
            {"rmse_mm", r.error().rmse_mm()},
            {"correlation", number_or_null(r.error().has_correlation(), r.error().correlation())},
            {"open_loop_mae_mm", r.open_loop_error().mae_mm()},
            {"open_loop_correlation",
             number_or_null(r.open_loop_error().has_correlation(), r.open_loop_error().correlation())},
            {"best_iteration", r.best_iteration()},
            {"best_again_mae_mm", number_or_null(r.best_again_job_id() != 0, r.best_again_error().mae_mm())},
            {"stop_reason", r.stop_reason()},
            {"model", model_json(r.model())},
            {"seconds", r.seconds()}}}};
}

int remote_render(const RemoteRenderArgs& args) {
  RemoteConnection connection(args.remote);
  auto stub = v1::RenderService::NewStub(connection.channel());
  v1::RenderRequest request;
  *request.mutable_array() = args.goal.array();
  *request.mutable_goal() = args.goal.goal();
  request.set_planner(args.goal.planner);
  request.set_iterations(args.iterations);
  request.set_correction(args.correction);
  request.set_gain(args.gain);
  request.set_name(args.name);
  request.set_keep_camera_plane(args.keep_camera_plane);
  const fs::path out(args.out);
  if (!args.out.empty()) fs::create_directories(out);

  auto context = connection.context(0);
  auto reader = stub->Render(context.get(), request);
  ProgressLine progress("remote render " + args.goal.label());
  v1::RenderEvent event;
  v1::RenderResult result;
  bool have_result = false;
  while (reader->Read(&event)) {
    if (event.has_progress()) {
      const auto& p = event.progress();
      progress.update(int(std::lround(p.fraction() * 100)), 100,
                      "iteration " + std::to_string(p.iteration()) + ": " + p.message());
    } else if (event.has_iteration()) {
      const v1::RenderIteration& it = event.iteration();
      if (!args.out.empty()) write_iteration(out, it);
      if (args.json) std::cout << iteration_line(it).dump() << std::endl;
      else {
        std::fprintf(stderr, "\niteration %d: MAE %.2f mm, RMSE %.2f mm, r %s (prediction MAE %.2f mm); %s\n",
                     it.iteration(), it.error().mae_mm(), it.error().rmse_mm(),
                     it.error().has_correlation() ? std::to_string(it.error().correlation()).substr(0, 6).c_str() : "-",
                     it.prediction_error().mae_mm(), it.correction().c_str());
        if (!it.screening().empty()) std::fprintf(stderr, "  its plan, screened: %s\n", it.screening().c_str());
        if (!it.refusal().empty())
          std::fprintf(stderr, "  the device refused step %d of %d (%s): captured after the steps before it\n",
                       it.steps_run(), it.plan().steps_size(), it.refusal().c_str());
      }
    } else if (event.has_result()) {
      result = event.result();
      have_result = true;
    }
  }
  progress.finish();
  check(reader->Finish(), "Render");
  if (!have_result) throw std::runtime_error("the server ended the render stream without a result");
  if (!args.out.empty()) {
    write_frame_csv(out / "goal.csv", points(result.goal_heights_mm(), result.point_rows(), result.point_cols()));
    std::ofstream(out / "result.json") << nlohmann::json::parse(to_json_line(result)).dump(1) << "\n";
  }
  if (args.json) {
    std::cout << result_line(result).dump() << std::endl;
  } else {
    std::printf("%s on %d x %d: %d iterations, best %d: MAE %.2f mm (open loop %.2f mm), RMSE %.2f mm, r %s; "
                "stopped at %s, %.1f s\n",
                args.goal.label().c_str(), args.goal.rows, args.goal.cols, result.iterations(), result.best_iteration(),
                result.error().mae_mm(), result.open_loop_error().mae_mm(), result.error().rmse_mm(),
                result.error().has_correlation() ? std::to_string(result.error().correlation()).substr(0, 6).c_str() : "-",
                result.stop_reason().c_str(), result.seconds());
    if (result.best_again_job_id() != 0)
      std::printf("the device was left at iteration %d's surface again (job %lld): MAE %.2f mm\n",
                  result.best_iteration(), static_cast<long long>(result.best_again_job_id()),
                  result.best_again_error().mae_mm());
  }
  return 0;
}

}  // namespace

int run_remote_render(const std::vector<std::string>& args) {
  static const std::string usage = std::string(kRenderUsage) + kRemoteGoalUsage + kRemoteCommonUsage;
  return run_remote_subcommand<RemoteRenderArgs>("render", usage.c_str(), args, parse_render, remote_render);
}

}  // namespace hj::cli
