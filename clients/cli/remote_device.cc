// remote submit, watch, job, cancel, status, stop, resume: the DeviceService.
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>

#include "calib/frame_csv.h"
#include "hapticjam/v1/device_service.grpc.pb.h"
#include "progress.h"
#include "remote_command.h"
#include "remote_connection.h"
#include "remote_messages.h"

namespace hj::cli {

namespace v1 = ::hapticjam::v1;
namespace fs = std::filesystem;

namespace {

const char* state_name(v1::JobState s) {
  switch (s) {
    case v1::JOB_STATE_QUEUED: return "queued";
    case v1::JOB_STATE_RUNNING: return "running";
    case v1::JOB_STATE_DONE: return "done";
    case v1::JOB_STATE_FAILED: return "failed";
    case v1::JOB_STATE_CANCELLED: return "cancelled";
    case v1::JOB_STATE_INTERRUPTED: return "interrupted";
    default: return "unknown";
  }
}

bool finished(v1::JobState s) {
  return s == v1::JOB_STATE_DONE || s == v1::JOB_STATE_FAILED || s == v1::JOB_STATE_CANCELLED ||
         s == v1::JOB_STATE_INTERRUPTED;
}

// How `submit --wait` and `watch --job` end: 0 done, else 3 failed,
// 4 cancelled, 5 interrupted (README "Remote commands").
int exit_code_for_job(v1::JobState s) {
  switch (s) {
    case v1::JOB_STATE_DONE: return 0;
    case v1::JOB_STATE_FAILED: return 3;
    case v1::JOB_STATE_CANCELLED: return 4;
    default: return 5;
  }
}

std::string job_line(const v1::Job& j) {
  std::string where;
  if (j.position() == 0) where = " (running)";
  else if (j.position() > 0) where = " #" + std::to_string(j.position()) + " in line";
  std::string line = "job " + std::to_string(j.id()) + " " + state_name(j.state()) + where + ", owner " + j.owner() +
                     ", step " + std::to_string(j.steps_done()) + "/" + std::to_string(j.steps_total());
  if (!j.name().empty()) line += ", \"" + j.name() + "\"";
  if (!j.error().empty()) line += ": " + j.error();
  return line;
}

void print_queue(const v1::QueueState& q, bool json) {
  if (json) {
    std::cout << to_json_line(q) << std::endl;
    return;
  }
  std::cout << "queue: " << (q.device_connected() ? "device connected" : "device OFFLINE")
            << (q.paused() ? ", PAUSED: " + q.pause_reason() : "") << ", " << q.jobs_size() << " job(s)\n";
  for (const auto& j : q.jobs()) std::cout << "  " << job_line(j) << "\n";
  std::cout.flush();
}

// Writes a job's frames as DIR/capture_NNN.csv (session frame format).
void save_captures(const v1::Job& job, const fs::path& dir) {
  for (int k = 0; k < job.captures_size(); ++k) {
    char name[32];
    std::snprintf(name, sizeof name, "capture_%03d.csv", k);
    write_frame_csv(dir / name, frame_heights(job.captures(k)));
  }
}

// Follows the queue until job `id` has finished, showing its steps on a
// progress line; its last state.
v1::JobState follow_job(v1::DeviceService::Stub& stub, const RemoteConnection& connection, std::int64_t id) {
  auto context = connection.context(0);
  v1::WatchQueueRequest request;
  request.set_recent_finished(16);
  auto reader = stub.WatchQueue(context.get(), request);
  ProgressLine progress("job " + std::to_string(id));
  v1::QueueState state;
  while (reader->Read(&state)) {
    for (const auto& j : state.jobs()) {
      if (j.id() != id) continue;
      const std::string where = j.position() > 0 ? std::to_string(j.position()) + " job(s) ahead" : state_name(j.state());
      progress.update(j.steps_done(), j.steps_total(), state.paused() ? "queue paused: " + state.pause_reason() : where);
      if (finished(j.state())) {
        progress.finish();
        context->TryCancel();
        return j.state();
      }
    }
  }
  progress.finish();
  check(reader->Finish(), "WatchQueue");
  throw std::runtime_error("the queue stream ended before job " + std::to_string(id) + " finished");
}

std::string with_common(const char* usage) { return std::string(usage) + kRemoteCommonUsage; }

std::int64_t parse_job_id(const std::string& text) { return parse_int("JOB", text, 1, 2'000'000'000); }

// ---- remote submit ----

constexpr const char* kSubmitUsage =
    "usage: hapticjam remote submit PLAN.json [--name TEXT] [--capture] [--wait [--out DIR]] [--json]\n"
    "Queues the steps of PLAN.json (what 'plan' and 'remote plan' write, a session.json,\n"
    "or a list of steps) on the shared device; prints the job and its place in the queue.\n"
    "  --name TEXT     a name for the job (default: the file name)\n"
    "  --capture       append a capture step (the surface once the plan is done)\n"
    "  --wait          follow the job until it ends; exit 0 done, 3 failed, 4 cancelled,\n"
    "                  5 interrupted\n"
    "  --out DIR       with --wait: write the captured frames as DIR/capture_NNN.csv and,\n"
    "                  if PLAN.json has predicted.csv beside it, print how far the last\n"
    "                  capture is from the predicted surface\n"
    "  --json          print the job as JSON\n";

struct SubmitArgs {
  RemoteOptions remote;
  std::string plan_file, name, out;
  bool capture = false, wait = false, json = false;
};

SubmitArgs parse_submit(const std::vector<std::string>& args) {
  SubmitArgs out;
  for (ArgCursor c(args); c.next();) {
    const std::string& a = c.arg();
    if (take_remote_flag(c, out.remote)) continue;
    if (a == "--name") out.name = c.value();
    else if (a == "--capture") out.capture = true;
    else if (a == "--wait") out.wait = true;
    else if (a == "--out") out.out = c.value();
    else if (a == "--json") out.json = true;
    else if (a[0] != '-' && out.plan_file.empty()) out.plan_file = a;
    else throw std::invalid_argument(a[0] == '-' ? "unknown option " + a : "unexpected argument \"" + a + "\"");
  }
  if (out.plan_file.empty()) throw std::invalid_argument("missing PLAN.json");
  if (!out.out.empty() && !out.wait) throw std::invalid_argument("--out needs --wait");
  finish_remote_options(out.remote);
  return out;
}

v1::Plan read_plan_file(const std::string& file) {
  std::ifstream in(file);
  if (!in) throw std::runtime_error("cannot read \"" + file + "\"");
  nlohmann::json doc;
  try {
    doc = nlohmann::json::parse(in);
  } catch (const nlohmann::json::parse_error& e) {
    throw std::runtime_error(file + ": not JSON: " + e.what());
  }
  return plan_from_steps_json(doc, file);
}

// The capture against predicted.csv beside the plan, on the plan's mesh.
void print_difference(const std::string& plan_file, const v1::CaptureFrame& frame) {
  const fs::path predicted_file = fs::path(plan_file).parent_path() / "predicted.csv";
  if (!fs::exists(predicted_file)) return;
  std::ifstream in(plan_file);
  const nlohmann::json doc = nlohmann::json::parse(in, nullptr, false);
  if (!doc.is_object() || !doc.contains("array")) return;
  const auto& array = doc["array"];
  const int rows = array.value("rows", 0), cols = array.value("cols", 0), segments = array.value("segments", 0);
  const double cell_mm = array.value("cell_size_mm", 38.0);
  if (rows < 1 || cols < 1 || segments < 1) return;
  const int point_rows = rows * segments + 1, point_cols = cols * segments + 1;
  const Eigen::MatrixXd predicted = read_frame_csv(predicted_file, point_rows, point_cols);
  // The predicted in-plane positions, when the plan came with them.
  const fs::path x_file = fs::path(plan_file).parent_path() / "predicted_x.csv";
  const fs::path y_file = fs::path(plan_file).parent_path() / "predicted_y.csv";
  Eigen::MatrixXd x_mm, y_mm;
  const bool positioned = fs::exists(x_file) && fs::exists(y_file);
  if (positioned) {
    x_mm = read_frame_csv(x_file, point_rows, point_cols);
    y_mm = read_frame_csv(y_file, point_rows, point_cols);
  }
  const SurfaceDifference d = compare_capture(frame, predicted, cell_mm / segments, positioned ? &x_mm : nullptr,
                                              positioned ? &y_mm : nullptr);
  std::printf("captured - predicted over %d mesh points: rms %.2f mm, max |d| %.2f mm, mean %+.2f mm\n", d.points,
              d.rms_mm, d.max_abs_mm, d.mean_mm);
}

int remote_submit(const SubmitArgs& args) {
  v1::SubmitJobRequest request;
  *request.mutable_plan() = read_plan_file(args.plan_file);
  if (args.capture) request.mutable_plan()->add_steps()->mutable_capture();
  request.set_name(args.name.empty() ? fs::path(args.plan_file).filename().string() : args.name);
  RemoteConnection connection(args.remote);
  auto stub = v1::DeviceService::NewStub(connection.channel());
  v1::SubmitJobResponse response;
  check(stub->SubmitJob(connection.context(30).get(), request, &response), "SubmitJob");
  if (args.json) std::cout << to_json_line(response.job()) << std::endl;
  else std::printf("submitted %s\n", job_line(response.job()).c_str()), std::fflush(stdout);
  if (!args.wait) return 0;

  const v1::JobState end = follow_job(*stub, connection, response.job().id());
  v1::GetJobRequest get;
  get.set_id(response.job().id());
  v1::Job job;
  check(stub->GetJob(connection.context(30).get(), get, &job), "GetJob");
  std::printf("%s, %d frame(s) captured\n", job_line(job).c_str(), job.captures_size());
  if (!args.out.empty()) {
    save_captures(job, args.out);
    if (job.captures_size() > 0) print_difference(args.plan_file, job.captures(job.captures_size() - 1));
  }
  return exit_code_for_job(end);
}

// ---- remote watch ----

constexpr const char* kWatchUsage =
    "usage: hapticjam remote watch [--job ID] [--once] [--recent N] [--json]\n"
    "Prints the device queue (running and queued jobs in order, their owners and\n"
    "progress) now and at every change, until interrupted.\n"
    "  --job ID        stop once job ID has ended; exit 0 done, 3 failed, 4 cancelled,\n"
    "                  5 interrupted\n"
    "  --once          print the queue once and exit\n"
    "  --recent N      also list the N most recently finished jobs (default 0)\n"
    "  --json          one QueueState per line as JSON\n";

struct WatchArgs {
  RemoteOptions remote;
  std::int64_t job = 0;
  bool once = false, json = false;
  int recent = 0;
};

WatchArgs parse_watch(const std::vector<std::string>& args) {
  WatchArgs out;
  for (ArgCursor c(args); c.next();) {
    const std::string& a = c.arg();
    if (take_remote_flag(c, out.remote)) continue;
    if (a == "--job") out.job = parse_job_id(c.value());
    else if (a == "--once") out.once = true;
    else if (a == "--recent") out.recent = parse_int(a, c.value(), 0, 1000);
    else if (a == "--json") out.json = true;
    else throw std::invalid_argument(a[0] == '-' ? "unknown option " + a : "unexpected argument \"" + a + "\"");
  }
  finish_remote_options(out.remote);
  return out;
}

int remote_watch(const WatchArgs& args) {
  RemoteConnection connection(args.remote);
  auto stub = v1::DeviceService::NewStub(connection.channel());
  auto context = connection.context(0);
  v1::WatchQueueRequest request;
  request.set_recent_finished(std::max(args.recent, args.job ? 16 : 0));
  auto reader = stub->WatchQueue(context.get(), request);
  v1::QueueState state;
  while (reader->Read(&state)) {
    print_queue(state, args.json);
    if (args.once) {
      context->TryCancel();
      return 0;
    }
    if (args.job)
      for (const auto& j : state.jobs())
        if (j.id() == args.job && finished(j.state())) {
          context->TryCancel();
          return exit_code_for_job(j.state());
        }
  }
  check(reader->Finish(), "WatchQueue");
  return 0;
}

// ---- remote job, cancel, status, stop, resume: one call each ----

struct OneCallArgs {
  RemoteOptions remote;
  std::int64_t job = 0;
  std::string out, reason;
  bool json = false;
};

// Parses the common flags, --json, and: a JOB id if `needs_job`, --out DIR if
// `takes_out`, --reason if `takes_reason`.
std::function<OneCallArgs(const std::vector<std::string>&)> one_call_parser(bool needs_job, bool takes_out,
                                                                            bool takes_reason) {
  return [=](const std::vector<std::string>& args) {
    OneCallArgs out;
    for (ArgCursor c(args); c.next();) {
      const std::string& a = c.arg();
      if (take_remote_flag(c, out.remote)) continue;
      if (a == "--json") out.json = true;
      else if (takes_out && a == "--out") out.out = c.value();
      else if (takes_reason && a == "--reason") out.reason = c.value();
      else if (needs_job && a[0] != '-' && out.job == 0) out.job = parse_job_id(a);
      else throw std::invalid_argument(a[0] == '-' ? "unknown option " + a : "unexpected argument \"" + a + "\"");
    }
    if (needs_job && out.job == 0) throw std::invalid_argument("missing JOB (a job id)");
    finish_remote_options(out.remote);
    return out;
  };
}

void print_status(const v1::DeviceStatus& s, bool json) {
  if (json) {
    v1::DeviceStatus brief = s;
    brief.mutable_last_capture()->clear_heights_mm();
    std::cout << to_json_line(brief) << "\n";
    return;
  }
  std::printf("device %s%s: %s, %d x %d cells, pressure %.0f Pa (max %.0f), %d jammed, %d pinned%s%s%s\n",
              s.endpoint().c_str(), s.connected() ? "" : " OFFLINE", s.connected() ? "connected" : "not connected",
              s.rows(), s.cols(), s.pressure_pa(), s.max_pressure_pa(), s.jammed_cells_size(), s.pinned_nodes_size(),
              s.emergency_stopped() ? ", EMERGENCY STOPPED" : "",
              s.queue_paused() ? (", queue paused: " + s.pause_reason()).c_str() : "",
              s.last_error().empty() ? "" : (", last error: " + s.last_error()).c_str());
  if (s.last_capture().heights_mm_size() > 0)
    std::printf("last capture: %d x %d samples at %g mm\n", s.last_capture().grid().nx(), s.last_capture().grid().ny(),
                s.last_capture().grid().dx_mm());
}

int remote_job(const OneCallArgs& args) {
  RemoteConnection connection(args.remote);
  auto stub = v1::DeviceService::NewStub(connection.channel());
  v1::GetJobRequest request;
  request.set_id(args.job);
  v1::Job job;
  check(stub->GetJob(connection.context(30).get(), request, &job), "GetJob");
  if (!args.out.empty()) save_captures(job, args.out);
  if (args.json) {
    v1::Job brief = job;
    brief.clear_captures();
    std::cout << to_json_line(brief) << "\n";
  } else {
    std::printf("%s, %d frame(s) captured%s\n", job_line(job).c_str(), job.captures_size(),
                args.out.empty() || job.captures_size() == 0 ? "" : (", written to " + args.out).c_str());
  }
  return 0;
}

int remote_cancel(const OneCallArgs& args) {
  RemoteConnection connection(args.remote);
  auto stub = v1::DeviceService::NewStub(connection.channel());
  v1::CancelJobRequest request;
  request.set_id(args.job);
  v1::CancelJobResponse response;
  check(stub->CancelJob(connection.context(30).get(), request, &response), "CancelJob");
  if (args.json) std::cout << to_json_line(response.job()) << "\n";
  else std::printf("%s\n", job_line(response.job()).c_str());
  return 0;
}

int remote_status(const OneCallArgs& args) {
  RemoteConnection connection(args.remote);
  auto stub = v1::DeviceService::NewStub(connection.channel());
  v1::DeviceStatus status;
  check(stub->GetDeviceStatus(connection.context(30).get(), v1::GetDeviceStatusRequest(), &status), "GetDeviceStatus");
  print_status(status, args.json);
  return 0;
}

int remote_stop(const OneCallArgs& args) {
  RemoteConnection connection(args.remote);
  auto stub = v1::DeviceService::NewStub(connection.channel());
  v1::EmergencyStopRequest request;
  request.set_reason(args.reason.empty() ? "emergency stop from the command line" : args.reason);
  v1::DeviceStatus status;
  check(stub->EmergencyStop(connection.context(30).get(), request, &status), "EmergencyStop");
  print_status(status, args.json);
  return 0;
}

int remote_resume(const OneCallArgs& args) {
  RemoteConnection connection(args.remote);
  auto stub = v1::DeviceService::NewStub(connection.channel());
  v1::QueueState state;
  check(stub->ResumeQueue(connection.context(30).get(), v1::ResumeQueueRequest(), &state), "ResumeQueue");
  print_queue(state, args.json);
  return 0;
}

}  // namespace

int run_remote_submit(const std::vector<std::string>& args) {
  static const std::string usage = with_common(kSubmitUsage);
  return run_remote_subcommand<SubmitArgs>("submit", usage.c_str(), args, parse_submit, remote_submit);
}

int run_remote_watch(const std::vector<std::string>& args) {
  static const std::string usage = with_common(kWatchUsage);
  return run_remote_subcommand<WatchArgs>("watch", usage.c_str(), args, parse_watch, remote_watch);
}

int run_remote_job(const std::vector<std::string>& args) {
  static const std::string usage =
      with_common("usage: hapticjam remote job ID [--out DIR] [--json]\n"
                  "One job: state, owner, progress, error; --out DIR writes its frames as DIR/capture_NNN.csv.\n");
  return run_remote_subcommand<OneCallArgs>("job", usage.c_str(), args, one_call_parser(true, true, false), remote_job);
}

int run_remote_cancel(const std::vector<std::string>& args) {
  static const std::string usage =
      with_common("usage: hapticjam remote cancel ID [--json]\n"
                  "Cancels a queued or running job (operator: own jobs; admin: any).\n");
  return run_remote_subcommand<OneCallArgs>("cancel", usage.c_str(), args, one_call_parser(true, false, false),
                                            remote_cancel);
}

int run_remote_status(const std::vector<std::string>& args) {
  static const std::string usage =
      with_common("usage: hapticjam remote status [--json]\n"
                  "The device: connection, array, pressure, jammed cells, pinned nodes, last capture,\n"
                  "whether the queue is paused and why.\n");
  return run_remote_subcommand<OneCallArgs>("status", usage.c_str(), args, one_call_parser(false, false, false),
                                            remote_status);
}

int run_remote_stop(const std::vector<std::string>& args) {
  static const std::string usage =
      with_common("usage: hapticjam remote stop [--reason TEXT] [--json]\n"
                  "Emergency stop (admin): vents the device at once, bypassing the queue, interrupts\n"
                  "the running job and pauses the queue until 'remote resume'.\n");
  return run_remote_subcommand<OneCallArgs>("stop", usage.c_str(), args, one_call_parser(false, false, true),
                                            remote_stop);
}

int run_remote_resume(const std::vector<std::string>& args) {
  static const std::string usage =
      with_common("usage: hapticjam remote resume [--json]\n"
                  "Lets a paused queue run again after a fault or a stop (admin).\n");
  return run_remote_subcommand<OneCallArgs>("resume", usage.c_str(), args, one_call_parser(false, false, false),
                                            remote_resume);
}

}  // namespace hj::cli
