// remote plan, remote preview, remote planners: the PlanningService.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>

#include "calib/frame_csv.h"
#include "compare_image.h"
#include "hapticjam/v1/planning_service.grpc.pb.h"
#include "progress.h"
#include "remote_command.h"
#include "remote_connection.h"
#include "remote_goal.h"
#include "remote_messages.h"

namespace hj::cli {

namespace v1 = ::hapticjam::v1;
namespace fs = std::filesystem;

namespace {

constexpr double kDefaultCellMm = 38.0;

std::string correlation_text(bool has, double value, const std::string& why) {
  if (!has) return "undefined (" + why + ")";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4f", value);
  return buf;
}

// ---- remote plan ----

constexpr const char* kPlanUsage =
    "usage: hapticjam remote plan GOAL|--map NAME --rows R --cols C --out DIR [options]\n"
    "Plans on the server, showing its progress live, and writes what local 'hapticjam plan'\n"
    "writes: DIR/plan.json (steps, correlation, Laplace mean), DIR/predicted.csv\n"
    "(heights) with DIR/predicted_x.csv and predicted_y.csv (in-plane positions),\n"
    "DIR/goal.csv, DIR/compare.png; with --snapshots also DIR/snapshots/NNN.csv, every\n"
    "surface snapshot the server streamed (mm per mesh point, row i along +y).\n"
    "  --out DIR             where to write\n"
    "  --snapshots           save the streamed snapshots (they are always counted)\n"
    "  --no-snapshots        ask the server for progress only\n"
    "  --json                print the summary as JSON\n";

struct RemotePlanArgs {
  RemoteOptions remote;
  GoalArgs goal;
  std::string out;
  bool save_snapshots = false, omit_snapshots = false, json = false;
};

RemotePlanArgs parse_plan(const std::vector<std::string>& args) {
  RemotePlanArgs out;
  for (ArgCursor c(args); c.next();) {
    const std::string& a = c.arg();
    if (take_remote_flag(c, out.remote) || out.goal.take(c)) continue;
    if (a == "--out") out.out = c.value();
    else if (a == "--snapshots") out.save_snapshots = true;
    else if (a == "--no-snapshots") out.omit_snapshots = true;
    else if (a == "--json") out.json = true;
    else throw std::invalid_argument(a[0] == '-' ? "unknown option " + a : "unexpected argument \"" + a + "\"");
  }
  out.goal.validate();
  if (out.out.empty()) throw std::invalid_argument("missing --out DIR");
  finish_remote_options(out.remote);
  return out;
}

int remote_plan(const RemotePlanArgs& args) {
  RemoteConnection connection(args.remote);
  auto stub = v1::PlanningService::NewStub(connection.channel());
  v1::PlanRequest request;
  *request.mutable_array() = args.goal.array();
  *request.mutable_goal() = args.goal.goal();
  request.set_planner(args.goal.planner);
  request.set_omit_snapshots(args.omit_snapshots);

  const fs::path out(args.out);
  fs::create_directories(out);
  auto context = connection.context(0);
  auto reader = stub->Plan(context.get(), request);
  ProgressLine progress("remote plan " + args.goal.label());
  v1::PlanEvent event;
  v1::PlanResult result;
  bool have_result = false;
  int snapshots = 0;
  while (reader->Read(&event)) {
    if (event.has_progress()) {
      progress.update(int(std::lround(event.progress().fraction() * 100)), 100, event.progress().message());
    } else if (event.has_snapshot()) {
      if (args.save_snapshots) {
        char name[32];
        std::snprintf(name, sizeof name, "%03d.csv", snapshots);
        write_frame_csv(out / "snapshots" / name, snapshot_heights(event.snapshot()));
      }
      ++snapshots;
    } else if (event.has_result()) {
      result = event.result();
      have_result = true;
    }
  }
  if (have_result) progress.update(100, 100, "done");
  progress.finish();
  check(reader->Finish(), "Plan");
  if (!have_result) throw std::runtime_error("the server ended the plan stream without a result");

  const Eigen::MatrixXd predicted = snapshot_heights(result.predicted());
  const Eigen::MatrixXd goal = goal_heights(result.goal_heights_mm(), predicted.rows(), predicted.cols());
  write_frame_csv(out / "predicted.csv", predicted);
  Eigen::MatrixXd x_mm, y_mm;
  if (snapshot_positions(result.predicted(), x_mm, y_mm)) {
    write_frame_csv(out / "predicted_x.csv", x_mm);
    write_frame_csv(out / "predicted_y.csv", y_mm);
  }
  write_frame_csv(out / "goal.csv", goal);
  // The mesh the server used follows from the surface it sent: R p + 1 points along y.
  const int segments = (predicted.rows() - 1) / args.goal.rows;
  const double cell_mm = args.goal.cell_mm > 0 ? args.goal.cell_mm : kDefaultCellMm;
  write_compare_png(out / "compare.png", Mesh(ArrayGeometry{args.goal.rows, args.goal.cols, cell_mm / 1000.0, segments}),
                    goal, predicted);

  const nlohmann::json steps = nlohmann::json::parse(result.steps_json());
  const nlohmann::json correlation = result.has_correlation() ? nlohmann::json(result.correlation()) : nlohmann::json(nullptr);
  nlohmann::json doc = {
      {"format", "hapticjam.plan/1"},
      {"goal", args.goal.map_name.empty() ? args.goal.file : "map:" + args.goal.map_name},
      {"array", {{"rows", args.goal.rows}, {"cols", args.goal.cols}, {"cell_size_mm", cell_mm}, {"segments", segments}}},
      {"planner", result.plan().planner()},
      {"server", args.remote.server},
      {"steps", steps},
      {"correlation", correlation},
      {"laplace_mean", result.laplace_mean()},
      {"snapshots", snapshots},
      {"cached", result.cached()}};
  if (args.goal.max_height_mm > 0) doc["max_height_mm"] = args.goal.max_height_mm;
  if (!result.has_correlation()) doc["correlation_undefined"] = result.correlation_undefined();
  doc["refused"] = result.refused_json().empty() ? nlohmann::json::array() : nlohmann::json::parse(result.refused_json());
  std::ofstream(out / "plan.json") << doc.dump(1) << "\n";

  if (args.json) {
    const nlohmann::json summary = {{"goal", doc["goal"]}, {"steps", steps.size()}, {"correlation", correlation},
                                    {"laplace_mean", result.laplace_mean()}, {"snapshots", snapshots},
                                    {"cached", result.cached()}, {"seconds", result.seconds()}, {"out", args.out}};
    std::cout << summary.dump() << "\n";
  } else {
    std::printf("%s on %d x %d: %zu steps, correlation %s, Laplace mean %.3f, %d snapshots%s, %.2f s on the server%s, "
                "written to %s\n",
                args.goal.label().c_str(), args.goal.rows, args.goal.cols, steps.size(),
                correlation_text(result.has_correlation(), result.correlation(), result.correlation_undefined()).c_str(),
                result.laplace_mean(), snapshots, args.save_snapshots ? " saved" : "", result.seconds(),
                result.cached() ? " (cached)" : "", args.out.c_str());
  }
  return 0;
}

// ---- remote preview ----

constexpr const char* kPreviewUsage =
    "usage: hapticjam remote preview GOAL|--map NAME --rows R --cols C [--out DIR] [--json] [options]\n"
    "The predicted surface and its scores, quickly (a coarse mesh of 2 segments per\n"
    "cell unless --segments says otherwise). Repeating a request is answered from the\n"
    "server's cache. --out DIR writes DIR/predicted.csv and DIR/goal.csv.\n";

struct RemotePreviewArgs {
  RemoteOptions remote;
  GoalArgs goal;
  std::string out;
  bool json = false;
};

RemotePreviewArgs parse_preview(const std::vector<std::string>& args) {
  RemotePreviewArgs out;
  for (ArgCursor c(args); c.next();) {
    const std::string& a = c.arg();
    if (take_remote_flag(c, out.remote) || out.goal.take(c)) continue;
    if (a == "--out") out.out = c.value();
    else if (a == "--json") out.json = true;
    else throw std::invalid_argument(a[0] == '-' ? "unknown option " + a : "unexpected argument \"" + a + "\"");
  }
  out.goal.validate();
  finish_remote_options(out.remote);
  return out;
}

int remote_preview(const RemotePreviewArgs& args) {
  RemoteConnection connection(args.remote);
  auto stub = v1::PlanningService::NewStub(connection.channel());
  v1::PreviewRequest request;
  *request.mutable_array() = args.goal.array();
  *request.mutable_goal() = args.goal.goal();
  request.set_planner(args.goal.planner);
  v1::PreviewResponse response;
  check(stub->Preview(connection.context(120).get(), request, &response), "Preview");
  if (!args.out.empty()) {
    const Eigen::MatrixXd predicted = snapshot_heights(response.predicted());
    write_frame_csv(fs::path(args.out) / "predicted.csv", predicted);
    write_frame_csv(fs::path(args.out) / "goal.csv",
                    goal_heights(response.goal_heights_mm(), predicted.rows(), predicted.cols()));
  }
  if (args.json) {
    v1::PreviewResponse brief = response;
    brief.clear_predicted();
    brief.clear_goal_heights_mm();
    std::cout << to_json_line(brief) << "\n";
  } else {
    std::printf("%s on %d x %d: %d steps, correlation %s, Laplace mean %.3f, %.3f s on the server%s\n",
                args.goal.label().c_str(), args.goal.rows, args.goal.cols, response.step_count(),
                correlation_text(response.has_correlation(), response.correlation(), response.correlation_undefined()).c_str(),
                response.laplace_mean(), response.seconds(), response.cached() ? " (cached)" : "");
  }
  return 0;
}

// ---- remote planners ----

constexpr const char* kPlannersUsage =
    "usage: hapticjam remote planners --server HOST:PORT [--json]\n"
    "The server's planners, the goal maps it holds and the goal formats it reads.\n";

struct RemotePlannersArgs {
  RemoteOptions remote;
  bool json = false;
};

RemotePlannersArgs parse_planners(const std::vector<std::string>& args) {
  RemotePlannersArgs out;
  for (ArgCursor c(args); c.next();) {
    if (take_remote_flag(c, out.remote)) continue;
    if (c.arg() == "--json") out.json = true;
    else throw std::invalid_argument("unexpected argument \"" + c.arg() + "\"");
  }
  finish_remote_options(out.remote);
  return out;
}

int remote_planners(const RemotePlannersArgs& args) {
  RemoteConnection connection(args.remote);
  auto stub = v1::PlanningService::NewStub(connection.channel());
  v1::ListPlannersResponse response;
  check(stub->ListPlanners(connection.context(30).get(), v1::ListPlannersRequest(), &response), "ListPlanners");
  if (args.json) {
    std::cout << to_json_line(response) << "\n";
    return 0;
  }
  auto join = [](const auto& list) {
    std::string s;
    for (const auto& x : list) s += (s.empty() ? "" : ", ") + x;
    return s.empty() ? std::string("(none)") : s;
  };
  std::cout << "planners: " << join(response.planners()) << "\nmaps: " << join(response.maps())
            << "\ngoal formats: " << join(response.goal_extensions()) << "\n";
  return 0;
}

std::string with_common(const char* usage, const char* more = "") {
  return std::string(usage) + more + kRemoteCommonUsage;
}

}  // namespace

int run_remote_plan(const std::vector<std::string>& args) {
  static const std::string usage = with_common(kPlanUsage, kRemoteGoalUsage);
  return run_remote_subcommand<RemotePlanArgs>("plan", usage.c_str(), args, parse_plan, remote_plan);
}

int run_remote_preview(const std::vector<std::string>& args) {
  static const std::string usage = with_common(kPreviewUsage, kRemoteGoalUsage);
  return run_remote_subcommand<RemotePreviewArgs>("preview", usage.c_str(), args, parse_preview, remote_preview);
}

int run_remote_planners(const std::vector<std::string>& args) {
  static const std::string usage = with_common(kPlannersUsage);
  return run_remote_subcommand<RemotePlannersArgs>("planners", usage.c_str(), args, parse_planners, remote_planners);
}

}  // namespace hj::cli
