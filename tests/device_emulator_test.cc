// The device emulator: its camera (noise like the shared sessions, seeded),
// its command line, and the real hapticjam-device-emulator program driven
// through the link as a subprocess.
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>

#include "device/asio_device_link.h"
#include "device/emulator_options.h"
#include "device_test_support.h"
#include "expect_error.h"
#include "scratch_dir.h"

extern char** environ;

namespace hj::device {
namespace {

using namespace std::chrono_literals;
using testing_support::expect_error;

constexpr auto kLong = 20s;

protocol::Request request(protocol::Command command, std::uint64_t id = 1) {
  protocol::Request r;
  r.id = id;
  r.command = command;
  return r;
}

Capture capture_from(Emulator& e) {
  const protocol::Reply reply = protocol::parse_reply(e.handle(request(protocol::Command::kCapture)));
  EXPECT_TRUE(reply.ok);
  return protocol::parse_capture(reply.text);
}

EmulatorConfig noisy_config(std::uint64_t seed) {
  EmulatorConfig config = testing_support::emulator_config_3x4();
  config.camera.noise_mm = 1.0;
  config.camera.resolution_mm = 1.0;
  config.camera.dropout = 0.01;
  config.camera.seed = seed;
  return config;
}

TEST(DeviceEmulator, CameraNoiseIsLikeTheSharedSessions) {
  Emulator noisy(noisy_config(7));
  protocol::Request pressure = request(protocol::Command::kAction);
  pressure.action = Action::set_pressure(1000.0);
  ASSERT_EQ(noisy.handle(pressure), "ok 1");
  const Eigen::MatrixXd exact = noisy.exact_frame();
  const Capture c = capture_from(noisy);
  int dropped = 0, seen = 0;
  double sum_sq = 0.0;
  for (Eigen::Index i = 0; i < exact.size(); ++i) {
    const double h = c.heights_mm.data()[i];
    if (std::isnan(h)) {
      ++dropped;
      continue;
    }
    EXPECT_EQ(h, std::round(h)) << "a whole mm";
    sum_sq += (h - exact.data()[i]) * (h - exact.data()[i]);
    ++seen;
  }
  // sigma 1 mm then rounding to 1 mm: rms sqrt(1 + 1/12) = 1.04 mm, as the
  // sessions' README says; 1 % of 4466 samples dropped.
  const double rms = std::sqrt(sum_sq / seen);
  EXPECT_NEAR(rms, 1.04, 0.06);
  EXPECT_GT(dropped, 15);
  EXPECT_LT(dropped, 90);
  // The same seed sees the same noise; another seed does not.
  Emulator same(noisy_config(7)), other(noisy_config(8));
  same.handle(pressure);
  other.handle(pressure);
  const Capture c_same = capture_from(same), c_other = capture_from(other);
  EXPECT_TRUE(c.heights_mm.array().isNaN().matrix() == c_same.heights_mm.array().isNaN().matrix());
  EXPECT_TRUE((c.heights_mm.array() == c_same.heights_mm.array() || c.heights_mm.array().isNaN()).all());
  EXPECT_FALSE((c.heights_mm.array() == c_other.heights_mm.array() || c.heights_mm.array().isNaN()).all());
}

TEST(DeviceEmulator, RefusesWhatTheDeviceCannotDo) {
  Emulator e(testing_support::emulator_config_3x4());
  protocol::Request r = request(protocol::Command::kAction, 5);
  r.action = Action::set_pressure(3451.0);
  EXPECT_EQ(e.handle(r), "err 5 unsafe unsafe pressure 3.451 kPa: must be within [0, 3.45] kPa");
  r.action = Action::unjam(0, 4);
  EXPECT_EQ(e.handle(r).rfind("err 5 out_of_range cell [0, 4] is out of range", 0), 0u);
  EXPECT_EQ(e.simulator().state().pressure_pa, 0.0);
}

// A settle past the settle timeout (1 ms: a 9 x 12 array's settle from rest
// to 2 kPa takes ten times that; a 3 x 4 one's may not) is answered "failed"
// with the state as before, as is one a vent stops; the next vent still ends
// at rest and answers ok.
TEST(DeviceEmulator, ASettlePastItsTimeoutOrStoppedFailsAndLeavesTheStateAsItWas) {
  EmulatorConfig config;
  config.geometry = {9, 12, 0.038, 4};
  config.params = SurfaceParameters::paper_defaults(config.geometry);
  config.camera.grid = device::default_capture_grid(config.geometry);
  config.settle_timeout = 1ms;
  Emulator e(config);
  protocol::Request r = request(protocol::Command::kAction, 4);
  r.action = Action::set_pressure(2000.0);
  const std::string timed_out = e.handle(r);
  EXPECT_EQ(timed_out.rfind("err 4 failed set_pressure 2 kPa: the membrane did not settle within 1 ms", 0), 0u)
      << timed_out;
  EXPECT_NE(timed_out.find("the state is as before the action"), std::string::npos);
  EXPECT_EQ(e.simulator().state().pressure_pa, 0.0);

  Emulator stoppable(testing_support::emulator_config_3x4());
  const std::string stopped = stoppable.handle(r, [] { return true; });
  EXPECT_EQ(stopped.rfind("err 4 failed set_pressure 2 kPa: stopped by a vent", 0), 0u) << stopped;
  EXPECT_EQ(stoppable.simulator().state().pressure_pa, 0.0);
  EXPECT_EQ(stoppable.handle(r), "ok 4");
  EXPECT_EQ(stoppable.handle(request(protocol::Command::kVent, 5)), "ok 5");
  EXPECT_EQ(stoppable.simulator().state().pressure_pa, 0.0);
}

// A vent whose settles are cut short (here by the config's own interrupt,
// as a timeout would) still ends at rest.
TEST(DeviceEmulator, AVentEndsAtRestEvenWhenItsSettlesAreCutShort) {
  auto cut_short = std::make_shared<bool>(false);
  EmulatorConfig config = testing_support::emulator_config_3x4();
  config.simulator.interrupted = [cut_short] { return *cut_short; };
  const Eigen::MatrixXd rest = Emulator(config).exact_frame();
  Emulator e(config);
  protocol::Request r = request(protocol::Command::kAction, 1);
  r.action = Action::set_pressure(2000.0);
  ASSERT_EQ(e.handle(r), "ok 1");
  r.action = Action::jam(1, 1);
  ASSERT_EQ(e.handle(r), "ok 1");
  r.action = Action::set_pressure(3000.0);
  ASSERT_EQ(e.handle(r), "ok 1");

  *cut_short = true;
  EXPECT_EQ(e.handle(request(protocol::Command::kVent, 2)), "ok 2");
  EXPECT_EQ(e.simulator().state().pressure_pa, 0.0);
  EXPECT_FALSE(e.simulator().state().jammed(e.simulator().mesh(), 1, 1));
  EXPECT_LT((e.exact_frame() - rest).cwiseAbs().maxCoeff(), 0.01);
}

TEST(DeviceEmulatorOptions, DefaultsAreTheSharedSessionsDevice) {
  const auto o = parse_emulator_options({"--listen", "127.0.0.1:0"});
  EXPECT_EQ(o.server.host, "127.0.0.1");
  EXPECT_EQ(o.server.port, 0);
  EXPECT_EQ(o.config.geometry.rows, 3);
  EXPECT_EQ(o.config.geometry.cols, 4);
  EXPECT_EQ(o.config.camera.grid.nx, 77);
  EXPECT_EQ(o.config.camera.grid.ny, 58);
  EXPECT_EQ(o.config.camera.noise_mm, 0.0);
  EXPECT_EQ(o.config.camera.resolution_mm, 0.0);
  EXPECT_EQ(o.config.params.max_pressure_pa, 3450.0);
  const auto n = parse_emulator_options({"--listen", "[::1]:7700", "--noise-mm", "1", "--rows", "2", "--cols", "2",
                                         "--grid", "10,5,1,2,3,4", "--max-pressure-kpa", "2", "--seed", "9"});
  EXPECT_EQ(n.server.host, "::1");
  EXPECT_EQ(n.server.port, 7700);
  EXPECT_EQ(n.config.camera.resolution_mm, 1.0);
  EXPECT_EQ(n.config.camera.dropout, 0.01);
  EXPECT_EQ(n.config.camera.grid.nx, 10);
  EXPECT_EQ(n.config.camera.grid.dy_mm, 4.0);
  EXPECT_EQ(n.config.params.max_pressure_pa, 2000.0);
  EXPECT_EQ(n.config.camera.seed, 9u);
  EXPECT_EQ(o.config.settle_timeout, 30s);
  EXPECT_EQ(parse_emulator_options({"--listen", "h:1", "--settle-timeout-s", "5"}).config.settle_timeout, 5s);
}

TEST(DeviceEmulatorOptions, BadFlagsNameTheFlag) {
  using Args = std::vector<std::string>;
  const auto bad = [](const Args& args, const std::vector<std::string>& words) {
    expect_error<std::invalid_argument>([&] { parse_emulator_options(args); }, words);
  };
  bad({}, {"missing --listen"});
  bad({"--listen", "7700"}, {"--listen", "HOST:PORT"});
  bad({"--listen", "h:70000"}, {"--listen port", "70000"});
  bad({"--listen", "h:1", "--rows", "0"}, {"--rows", "\"0\""});
  bad({"--listen", "h:1", "--segments", "x"}, {"--segments", "\"x\""});
  bad({"--listen", "h:1", "--cell-mm", "-3"}, {"--cell-mm"});
  bad({"--listen", "h:1", "--grid", "1,2,3"}, {"--grid", "nx,ny,x0,y0,dx,dy"});
  bad({"--listen", "h:1", "--grid", "10,10,0,0,0,1"}, {"--grid", "positive"});
  bad({"--listen", "h:1", "--effects", "nosuch"}, {"--effects", "nosuch", "gravity"});
  bad({"--listen", "h:1", "--effects", "gravity"}, {"--effects", "gravity", "baseline"});
  bad({"--listen", "h:1", "--effects", ","}, {"--effects", "empty"});
  bad({"--listen", "h:1", "--noise-mm", "-1"}, {"--noise-mm"});
  bad({"--listen", "h:1", "--noise-mm", "nan"}, {"--noise-mm", "finite"});
  bad({"--listen", "h:1", "--dropout", "1"}, {"--dropout", "[0, 1)"});
  bad({"--listen", "h:1", "--max-pressure-kpa", "0"}, {"--max-pressure-kpa"});
  bad({"--listen", "h:1", "--params", "/nonexistent/params.json"}, {"--params", "/nonexistent/params.json"});
  bad({"--listen", "h:1", "--drop-after"}, {"--drop-after needs a value"});
  bad({"--listen", "h:1", "--settle-timeout-s", "0"}, {"--settle-timeout-s", "\"0\""});
  bad({"--listen", "h:1", "--frobnicate"}, {"unknown argument", "--frobnicate"});
}

TEST(DeviceEmulatorOptions, ParamsFileReachesTheSimulator) {
  testing_support::ScratchDir dir;
  const auto file = dir.path / "params.json";
  std::ofstream(file) << R"({"format": "hapticjam.params/1", "surface": {"mass_kg": 0.52, "spring_k": 58}})";
  const auto o = parse_emulator_options({"--listen", "h:1", "--params", file.string(), "--max-pressure-kpa", "3"});
  EXPECT_EQ(o.config.params.mass_kg, 0.52);
  EXPECT_EQ(o.config.params.spring_k, 58.0);
  EXPECT_EQ(o.config.params.kappa_jam, 4.79);  // not in the file: the default
  EXPECT_EQ(o.config.params.max_pressure_pa, 3000.0);
  std::ofstream(file) << R"({"format": "hapticjam.params/1", "surface": {"spring_k": "stiff"}})";
  expect_error<std::invalid_argument>(
      [&] { parse_emulator_options({"--listen", "h:1", "--params", file.string()}); }, {"--params", "spring_k"});
}

// The program itself, started with --drop-after 2, through the link.
class EmulatorProcess {
 public:
  explicit EmulatorProcess(const std::vector<std::string>& args) {
    int out[2];
    if (pipe(out) != 0) throw std::runtime_error("pipe");
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_adddup2(&actions, out[1], STDOUT_FILENO);
    posix_spawn_file_actions_addclose(&actions, out[0]);
    std::vector<std::string> all = {HJ_EMULATOR_PATH};
    all.insert(all.end(), args.begin(), args.end());
    std::vector<char*> argv;
    for (auto& a : all) argv.push_back(a.data());
    argv.push_back(nullptr);
    const int rc = posix_spawn(&pid_, HJ_EMULATOR_PATH, &actions, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    close(out[1]);
    if (rc != 0) throw std::runtime_error("cannot start " + std::string(HJ_EMULATOR_PATH));
    out_ = fdopen(out[0], "r");
  }
  ~EmulatorProcess() {
    if (pid_ > 0) terminate();
    if (out_) fclose(out_);
  }
  std::string read_line() {
    char line[512];
    return fgets(line, sizeof line, out_) ? std::string(line) : std::string();
  }
  // SIGTERM; the exit code (-1 if it did not exit normally).
  int terminate() {
    kill(pid_, SIGTERM);
    int status = 0;
    waitpid(pid_, &status, 0);
    pid_ = -1;
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  }

 private:
  pid_t pid_ = -1;
  FILE* out_ = nullptr;
};

TEST(DeviceEmulatorProgram, ServesTheLinkDropsOnCueAndStopsOnSigterm) {
  EmulatorProcess process({"--listen", "127.0.0.1:0", "--drop-after", "2", "--noise-mm", "1", "--seed", "3"});
  const std::string banner = process.read_line();
  const std::size_t colon = banner.find("127.0.0.1:");
  ASSERT_NE(colon, std::string::npos) << banner;
  const std::string port = banner.substr(colon + 10, banner.find(' ', colon) - colon - 10);

  LinkOptions options;
  options.backoff_initial = 10ms;
  options.backoff_max = 100ms;
  AsioDeviceLink link(parse_endpoint("127.0.0.1:" + port), options);
  testing_support::ConnectionEvents events;
  link.on_connection_change(events.callback());
  link.start();
  ASSERT_TRUE(events.reach(1));
  EXPECT_EQ(link.status().max_pressure_pa, 3450.0);
  link.execute(Action::set_pressure(301.0), kLong);
  const Capture c = link.capture(kLong);
  EXPECT_EQ(c.grid.nx, 77);
  EXPECT_EQ(c.grid.ny, 58);
  EXPECT_TRUE((c.heights_mm.array() == c.heights_mm.array().round() || c.heights_mm.array().isNaN()).all());
  // The third command is dropped unanswered, then the link comes back.
  try {
    link.execute(Action::jam(0, 0), kLong);
    ADD_FAILURE() << "the emulator did not drop the link";
  } catch (const DeviceError& e) {
    EXPECT_EQ(e.kind(), DeviceError::Kind::kDisconnected) << e.what();
  }
  ASSERT_TRUE(events.reach(3));
  // The closed connection counts as silence: the device vented itself.
  EXPECT_EQ(link.query_status(kLong).pressure_pa, 0.0);
  // Told to stall over the protocol: a command times out, pings go on.
  EXPECT_EQ(link.send_raw("fault stall 400", kLong), "");
  expect_error<DeviceError>([&] { link.capture(50ms); }, {"capture", "no reply within 50 ms"});
  link.ping(kLong);
  expect_error<DeviceError>([&] { link.send_raw("fault explode", kLong); }, {"malformed", "unknown fault"});
  link.stop();
  EXPECT_EQ(process.terminate(), 0);
}

TEST(DeviceEmulatorProgram, HelpListsEveryFlagAndBadFlagsExitTwo) {
  testing_support::ScratchDir dir;
  const std::string out = (dir.path / "out.txt").string();
  const std::string exe = std::string("'") + HJ_EMULATOR_PATH + "'";
  ASSERT_EQ(std::system((exe + " --help >'" + out + "' 2>&1").c_str()), 0);
  std::ifstream in(out);
  const std::string help((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  for (const char* flag : {"--listen", "--rows", "--cols", "--segments", "--cell-mm", "--params", "--effects",
                           "--max-pressure-kpa", "--grid", "--noise-mm", "--resolution-mm", "--dropout", "--seed",
                           "--drop-after", "--help"})
    EXPECT_NE(help.find(flag), std::string::npos) << flag;
  const int status = std::system((exe + " --listen 127.0.0.1:0 --rows 0 >'" + out + "' 2>&1").c_str());
  EXPECT_EQ(WEXITSTATUS(status), 2);
  std::ifstream err(out);
  const std::string message((std::istreambuf_iterator<char>(err)), std::istreambuf_iterator<char>());
  EXPECT_NE(message.find("--rows"), std::string::npos) << message;
}

}  // namespace
}  // namespace hj::device
