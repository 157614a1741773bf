// The render job end to end: the real hapticjam-server and a real
// hapticjam-device-emulator whose model the planner was not given
// (stiffening and a soft middle, a finer mesh, a noisy camera), on loopback,
// driven by `hapticjam remote render --json`. The goal is one the device can
// make (its own surface after a known sequence), so the loop can reach it.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "render_support.h"
#include "scratch_dir.h"

namespace hj {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;
using testing_support::EmulatorLine;
using testing_support::wait_until;

// A device the planner's baseline model does not know.
const char* const kUnknownDevice = R"({"format": "hapticjam.params/1",
  "effects": {"stiffening": {"beta": 30}, "cell_stiffness": {"bulge": -0.3}}})";

const std::vector<std::string> kKnownSequence = {"set_pressure 1200", "jam 0 1", "pin 1 1", "set_pressure 2400",
                                                 "jam 1 2", "jam 2 0", "set_pressure 3000"};

// Stiffening and a camera tilted about both axes.
constexpr double kTiltXMrad = 15.0, kTiltYMrad = -10.0;
const char* const kTiltedDevice = R"({"format": "hapticjam.params/1",
  "effects": {"stiffening": {"beta": 30}, "sensor_tilt": {"tilt_x_mrad": 15, "tilt_y_mrad": -10}}})";

struct RenderRig {
  explicit RenderRig(const char* device = kUnknownDevice) {
    std::ofstream(dir.path / "device.json") << device;
    emulator = std::make_unique<testing_support::Emulator>(
        dir.path, std::vector<std::string>{"--params", (dir.path / "device.json").string(), "--segments", "8",
                                           "--noise-mm", "1", "--seed", "7"});
    goal = testing_support::make_goal(emulator->port, mesh, kKnownSequence, dir.path / "goal.csv");
    server = std::make_unique<testing_support::Server>(
        dir.path, dir.path / "queue.db", std::vector<std::string>{"--device", emulator->endpoint()});
  }
  testing_support::CliResult cli(std::vector<std::string> args) {
    args.insert(args.begin(), "remote");
    args.insert(args.end(), {"--server", server->address()});
    return testing_support::run_cli(args, dir.path);
  }
  bool connected() {
    const auto r = cli({"status", "--json"});
    return r.code == 0 && json::parse(r.out).value("connected", false);
  }

  testing_support::ScratchDir dir;
  const Mesh mesh{ArrayGeometry{3, 4, 0.038, 4}};  // the planner's mesh
  Eigen::MatrixXd goal;
  std::unique_ptr<testing_support::Emulator> emulator;
  std::unique_ptr<testing_support::Server> server;
};

std::vector<json> json_lines(const std::string& text) {
  std::vector<json> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);)
    if (!line.empty()) out.push_back(json::parse(line));
  return out;
}

TEST(RenderE2e, TheErrorFallsFromTheFirstIterationToTheLastAndTheTrueSurfaceImproves) {
  RenderRig rig;
  ASSERT_TRUE(wait_until([&] { return rig.connected(); })) << rig.server->process->err();
  const auto r = rig.cli({"render", (rig.dir.path / "goal.csv").string(), "--rows", "3", "--cols", "4",
                          "--segments", "4", "--iterations", "3", "--heights", "absolute", "--json", "--out",
                          (rig.dir.path / "render").string()});
  ASSERT_EQ(r.code, 0) << r.err << rig.server->process->err();
  const auto lines = json_lines(r.out);
  ASSERT_GE(lines.size(), 3u) << r.out;  // at least two iterations and the result
  const json& first = lines.front();
  const json& last = lines[lines.size() - 2];
  const json& result = lines.back()["result"];
  for (const char* key : {"iteration", "mae_mm", "rmse_mm", "correlation", "correction"})
    EXPECT_TRUE(first.contains(key)) << key << " missing in " << first;
  for (const char* key : {"iterations", "mae_mm", "rmse_mm", "correlation", "open_loop_mae_mm"})
    EXPECT_TRUE(result.contains(key)) << key << " missing in " << result;
  EXPECT_EQ(first["iteration"], 1);
  // The default correction: after the first run, the model fitted on the
  // device's probe; the second plan is the fitted model's (its targets
  // corrected by its own prediction), and every plan after it, of learned
  // targets, was screened.
  ASSERT_TRUE(first["model"].is_object()) << first;
  EXPECT_GT(first["model"]["probe_job_id"].get<long>(), first["job_id"].get<long>()) << first;
  EXPECT_TRUE(first["screening"].is_null()) << first;
  ASSERT_TRUE(lines[1]["screening"].is_string()) << lines[1];
  EXPECT_NE(lines[1]["screening"].get<std::string>().find("refitted model"), std::string::npos) << lines[1];
  for (std::size_t k = 2; k + 1 < lines.size(); ++k) {
    ASSERT_TRUE(lines[k]["screening"].is_string()) << lines[k];
    EXPECT_NE(lines[k]["screening"].get<std::string>().find("expected"), std::string::npos) << lines[k];
  }
  EXPECT_LT(last["mae_mm"].get<double>(), first["mae_mm"].get<double>()) << r.out;
  EXPECT_DOUBLE_EQ(result["open_loop_mae_mm"].get<double>(), first["mae_mm"].get<double>());
  EXPECT_LE(result["mae_mm"].get<double>(), last["mae_mm"].get<double>());
  EXPECT_TRUE(fs::exists(rig.dir.path / "render" / "iteration-1" / "capture.csv"));
  EXPECT_TRUE(fs::exists(rig.dir.path / "render" / "result.json"));

  // The device is left showing the best run: a later, worse run is followed
  // by the best run's steps again, whose capture is as far from the goal as
  // the best's was (the same surface, other camera noise).
  const int best = result["best_iteration"].get<int>();
  if (best != result["iterations"].get<int>()) {
    ASSERT_TRUE(result["best_again_mae_mm"].is_number()) << result;
    EXPECT_NEAR(result["best_again_mae_mm"].get<double>(), result["mae_mm"].get<double>(), 0.5) << result;
  } else {
    EXPECT_TRUE(result["best_again_mae_mm"].is_null()) << result;
  }
  // Its true surface (no camera noise) is nearer the goal than the
  // open-loop plan's picture was, and about as near as the best run's.
  EmulatorLine line(rig.emulator->port);
  const HeightError truth = height_error(rig.goal, testing_support::true_surface(line, rig.mesh));
  EXPECT_LT(truth.mae_mm, first["mae_mm"].get<double>());
  EXPECT_LT(truth.mae_mm, result["mae_mm"].get<double>() + 1.0) << "the device was not left at the best run";
}

// A tilted camera is a measurement effect: the model correction fits
// sensor_tilt from the captures (near the emulator's), takes it out of them
// rather than learning it into the surface, and the true surface (read from
// the emulator, no camera) ends nearer the goal than the open-loop plan's.
TEST(RenderE2e, TheModelCorrectionFitsTheCameraTiltAndTheTrueSurfaceImproves) {
  RenderRig rig(kTiltedDevice);
  ASSERT_TRUE(wait_until([&] { return rig.connected(); })) << rig.server->process->err();
  const std::vector<std::string> render = {"render", (rig.dir.path / "goal.csv").string(), "--rows", "3", "--cols",
                                           "4", "--segments", "4", "--heights", "absolute", "--json"};
  auto with = [&](std::vector<std::string> extra) {
    std::vector<std::string> args = render;
    args.insert(args.end(), extra.begin(), extra.end());
    return args;
  };
  // The open loop's true surface: one run of the plan alone.
  const auto open = rig.cli(with({"--iterations", "1", "--correction", "none"}));
  ASSERT_EQ(open.code, 0) << open.err << rig.server->process->err();
  double open_truth_mae = 0.0;
  {
    EmulatorLine line(rig.emulator->port);
    open_truth_mae = height_error(rig.goal, testing_support::true_surface(line, rig.mesh)).mae_mm;
  }

  // Two iterations: after the first run the device's probe finds the tilt
  // and the stiffening; the second plans with them.
  const auto r = rig.cli(with({"--iterations", "2", "--correction", "model", "--out", (rig.dir.path / "render").string()}));
  ASSERT_EQ(r.code, 0) << r.err << rig.server->process->err();
  const auto lines = json_lines(r.out);
  ASSERT_EQ(lines.size(), 3u) << r.out;
  const json& model = lines[0]["model"];
  ASSERT_TRUE(model.is_object()) << lines[0];
  EXPECT_GT(model["probe_job_id"].get<long>(), lines[0]["job_id"].get<long>()) << model;
  EXPECT_EQ(model["captures"].get<int>(), int(model["probe_pressures_kpa"].size()) + 1) << model;
  const json& p = model["parameters"];
  ASSERT_TRUE(p.contains("sensor_tilt.tilt_x_mrad")) << model;
  // 1 mm camera noise over a few thousand samples a capture: the tilt is
  // found to well within 2 mrad (0.15 mm across the array's width).
  EXPECT_NEAR(p["sensor_tilt.tilt_x_mrad"].get<double>(), kTiltXMrad, 2.0) << model;
  EXPECT_NEAR(p["sensor_tilt.tilt_y_mrad"].get<double>(), kTiltYMrad, 2.0) << model;
  for (size_t i = 0; i + 1 < lines.size(); ++i) {
    EXPECT_EQ(lines[i]["camera_source"], "fitted sensor_tilt") << lines[i];
    EXPECT_NEAR(lines[i]["camera_tilt_mrad"][0].get<double>(), kTiltXMrad, 2.0) << lines[i];
  }
  EXPECT_TRUE(fs::exists(rig.dir.path / "render" / "iteration-1" / "model.json"));
  EXPECT_TRUE(lines.back()["result"]["model"].is_object()) << lines.back();

  EmulatorLine line(rig.emulator->port);
  const HeightError truth = height_error(rig.goal, testing_support::true_surface(line, rig.mesh));
  EXPECT_LT(truth.mae_mm, open_truth_mae) << r.out;
}

TEST(RenderE2e, AnArraySizeOtherThanTheDevicesIsRefusedBeforeAnythingRuns) {
  RenderRig rig;
  ASSERT_TRUE(wait_until([&] { return rig.connected(); })) << rig.server->process->err();
  const auto r = rig.cli({"render", (rig.dir.path / "goal.csv").string(), "--rows", "2", "--cols", "4",
                          "--heights", "absolute", "--json"});
  EXPECT_EQ(r.code, 19) << r.err;  // FAILED_PRECONDITION
  EXPECT_NE(r.err.find("3 x 4"), std::string::npos) << r.err;
}

// A device is not the model: a step it cannot complete (here the emulator's
// injected refusal of the 4th action) ends that iteration where the device
// stood, captured and corrected there, and the loop goes on; the queue is
// not paused, since a refusal is not a fault.
TEST(RenderE2e, AStepTheDeviceRefusesEndsThatIterationWhereItStoodAndTheLoopGoesOn) {
  RenderRig rig;
  ASSERT_TRUE(wait_until([&] { return rig.connected(); })) << rig.server->process->err();
  {
    EmulatorLine line(rig.emulator->port);
    const std::string armed = line.request("fault refuse 4");
    ASSERT_EQ(armed.rfind("ok", 0), 0u) << armed;
  }
  const auto r = rig.cli({"render", (rig.dir.path / "goal.csv").string(), "--rows", "3", "--cols", "4",
                          "--iterations", "2", "--heights", "absolute", "--json", "--out",
                          (rig.dir.path / "render").string()});
  ASSERT_EQ(r.code, 0) << r.err << rig.server->process->err();
  const auto lines = json_lines(r.out);
  ASSERT_EQ(lines.size(), 3u) << r.out;
  const json& first = lines[0];
  ASSERT_TRUE(first["refusal"].is_string()) << first;
  EXPECT_NE(first["refusal"].get<std::string>().find("refused"), std::string::npos) << first;
  EXPECT_EQ(first["steps_run"], 3) << first;
  EXPECT_TRUE(std::isfinite(first["mae_mm"].get<double>())) << first;
  EXPECT_TRUE(lines[1]["refusal"].is_null()) << lines[1];
  EXPECT_GT(lines[1]["steps_run"].get<int>(), 3) << lines[1];
  EXPECT_EQ(lines[2]["result"]["iterations"], 2) << lines[2];
  const json plan = json::parse(testing_support::read_file(rig.dir.path / "render" / "iteration-1" / "plan.json"));
  EXPECT_EQ(plan["steps_run"], 3) << plan;
  EXPECT_GT(plan["refused_job_id"].get<long>(), 0) << plan;
  const auto status = rig.cli({"status", "--json"});
  EXPECT_FALSE(json::parse(status.out).value("queue_paused", true)) << status.out;
}

// An emergency stop during an iteration's job ends the render (ABORTED,
// naming the job), and the queue stays paused: nothing of the render runs on.
TEST(RenderE2e, AnEmergencyStopMidLoopEndsTheRender) {
  RenderRig rig;
  ASSERT_TRUE(wait_until([&] { return rig.connected(); })) << rig.server->process->err();
  // Hold the device's commands so the first job is surely running when the stop comes.
  EmulatorLine line(rig.emulator->port);
  line.request("fault stall 3000");
  const std::string cli = std::string(HJ_CLI_PATH);
  testing_support::Process render({cli, "remote", "render", (rig.dir.path / "goal.csv").string(), "--rows", "3",
                                   "--cols", "4", "--iterations", "3", "--heights", "absolute", "--json", "--server",
                                   rig.server->address()},
                                  rig.dir.path / "render.out", rig.dir.path / "render.err");
  ASSERT_TRUE(wait_until([&] {
    const auto r = rig.cli({"watch", "--once", "--json"});
    return r.code == 0 && r.out.find("JOB_STATE_RUNNING") != std::string::npos;
  }, 120));
  const auto stop = rig.cli({"stop", "--reason", "test"});
  EXPECT_EQ(stop.code, 0) << stop.err;
  EXPECT_EQ(render.wait(), 20) << render.err();  // 10 + ABORTED
  EXPECT_NE(render.err().find("iteration 1"), std::string::npos) << render.err();
  const auto status = rig.cli({"status", "--json"});
  EXPECT_TRUE(json::parse(status.out).value("queue_paused", false)) << status.out;
}

}  // namespace
}  // namespace hj
