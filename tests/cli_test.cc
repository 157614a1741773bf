// The hapticjam command line (clients/cli): `simulate` replays a session and
// writes one frame per capture on the session's grid; a malformed session
// or option exits non-zero with a message naming what is wrong.
#include <gtest/gtest.h>

#include "cli_runner.h"
#include "scratch_dir.h"

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "calib/frame_csv.h"

namespace hj {
namespace {

namespace fs = std::filesystem;

const fs::path kPaperSequence = fs::path(HJ_SHARED_DIR) / "data/sessions/demo-baseline/paper-sequence";

using testing_support::ScratchDir;

using testing_support::quoted;
using testing_support::read_text;
using testing_support::run_cli;

const std::string kTrueParameters = " --mass 0.52 --k 58 --kappa-jam 4.2";

TEST(Cli, SimulateWritesEveryCaptureFrame) {
  ScratchDir dir;
  const fs::path out = dir.path / "out";
  ASSERT_EQ(run_cli("simulate " + quoted(kPaperSequence / "session.json") + kTrueParameters + " --out " + quoted(out),
                    dir.path),
            0)
      << read_text(dir.path / "stderr.txt");
  for (const char* frame : {"frames/000.csv", "frames/001.csv", "frames/002.csv", "frames/003.csv"}) {
    SCOPED_TRACE(frame);
    ASSERT_TRUE(fs::exists(out / frame));
    // 58 lines of 77 finite numbers (mm).
    std::ifstream in(out / frame);
    std::string line;
    int lines = 0;
    while (std::getline(in, line)) {
      ++lines;
      std::stringstream fields(line);
      std::string field;
      int n = 0;
      while (std::getline(fields, field, ',')) {
        size_t used = 0;
        const double v = std::stod(field, &used);
        EXPECT_EQ(used, field.size()) << "line " << lines << " field " << n << ": \"" << field << "\"";
        EXPECT_TRUE(std::isfinite(v)) << "line " << lines << " field " << n;
        ++n;
      }
      EXPECT_EQ(n, 77) << "line " << lines;
    }
    EXPECT_EQ(lines, 58);
    // And the prediction matches the dataset's capture to the noise floor.
    const Eigen::MatrixXd predicted = read_frame_csv(out / frame, 58, 77);
    const Eigen::MatrixXd real = read_frame_csv(kPaperSequence / frame, 58, 77);
    double sum = 0.0;
    int count = 0;
    for (int i = 0; i < real.size(); ++i)
      if (!std::isnan(real(i)) && !std::isnan(predicted(i))) sum += std::abs(real(i) - predicted(i)), ++count;
    EXPECT_LE(sum / count, 1.2);
  }
}

TEST(Cli, MalformedSessionNamesTheStepAndKey) {
  ScratchDir dir;
  nlohmann::json session = nlohmann::json::parse(read_text(kPaperSequence / "session.json"));
  int bad_step = -1;
  for (size_t i = 0; i < session["steps"].size() && bad_step < 0; ++i)
    if (session["steps"][i]["op"] == "jam") {
      session["steps"][i]["cell"] = {7, 0};
      bad_step = static_cast<int>(i);
    }
  ASSERT_GE(bad_step, 0);
  std::ofstream(dir.path / "session.json") << session.dump(1);

  const int code = run_cli("simulate " + quoted(dir.path / "session.json") + " --out " + quoted(dir.path / "out"),
                           dir.path);
  EXPECT_NE(code, 0);
  const std::string err = read_text(dir.path / "stderr.txt");
  EXPECT_NE(err.find("steps[" + std::to_string(bad_step) + "]"), std::string::npos) << err;
  EXPECT_NE(err.find("cell"), std::string::npos) << err;
  EXPECT_FALSE(fs::exists(dir.path / "out" / "frames" / "000.csv")) << "no frames from a refused session";
}

TEST(Cli, TooFewSegmentsIsAUsageError) {
  ScratchDir dir;
  const int code = run_cli("simulate " + quoted(kPaperSequence / "session.json") + " --segments 1 --out " +
                               quoted(dir.path / "out"),
                           dir.path);
  EXPECT_EQ(code, 2);
  EXPECT_NE(read_text(dir.path / "stderr.txt").find("--segments"), std::string::npos);
}

// An output folder the demo cannot write its session into (in a container: a
// volume owned by another user) is named as such. A folder in the way of
// session.json fails the same write even for root, who ignores permissions.
TEST(Cli, DemoNamesTheSessionFileItCannotWrite) {
  ScratchDir dir;
  const fs::path out = dir.path / "out";
  fs::create_directories(out / "session.json");
  EXPECT_EQ(run_cli("demo --out " + quoted(out), dir.path), 1);
  const std::string err = read_text(dir.path / "stderr.txt");
  EXPECT_NE(err.find((out / "session.json").string() + ": cannot write the demo session (Is a directory)"),
            std::string::npos)
      << err;
  EXPECT_EQ(err.find("cannot open session file"), std::string::npos) << err;
  EXPECT_FALSE(fs::exists(out / "frames"));
}

// An --out below a regular file cannot be created; the message names it.
TEST(Cli, DemoNamesAnOutputFolderItCannotCreate) {
  ScratchDir dir;
  std::ofstream(dir.path / "file") << "x";
  const fs::path out = dir.path / "file" / "out";
  EXPECT_EQ(run_cli("demo --out " + quoted(out), dir.path), 1);
  const std::string err = read_text(dir.path / "stderr.txt");
  EXPECT_NE(err.find(out.string() + ": cannot create the output folder"), std::string::npos) << err;
}

}  // namespace
}  // namespace hj

namespace hj {
namespace {

TEST(Cli, PlanWritesAReplayablePlanForARealDem) {
  ScratchDir dir;
  const fs::path out = dir.path / "plan";
  const fs::path dem = fs::path(HJ_SHARED_DIR) / "data/dem/volcano_maunga_whau.csv";
  ASSERT_EQ(run_cli("plan " + quoted(dem) + " --rows 3 --cols 4 --out " + quoted(out), dir.path), 0)
      << read_text(dir.path / "stderr.txt");
  const auto plan = nlohmann::json::parse(read_text(out / "plan.json"));
  ASSERT_TRUE(plan["correlation"].is_number());
  EXPECT_GT(plan["correlation"].get<double>(), 0.5);
  EXPECT_GT(plan["laplace_mean"].get<double>(), 0.0);
  ASSERT_FALSE(plan["steps"].empty());
  for (const auto& step : plan["steps"]) EXPECT_TRUE(step.contains("op"));
  EXPECT_TRUE(fs::exists(out / "compare.png"));
  EXPECT_EQ(read_frame_csv(out / "predicted.csv", 13, 17).rows(), 13);
}

TEST(Cli, PlanRejectsACorruptGoalWithItsName) {
  ScratchDir dir;
  std::ofstream(dir.path / "broken.png") << "not a png";
  EXPECT_NE(run_cli("plan " + quoted(dir.path / "broken.png") + " --rows 3 --cols 4 --out " + quoted(dir.path / "o"), dir.path), 0);
  EXPECT_NE(read_text(dir.path / "stderr.txt").find("broken.png"), std::string::npos);
}

}  // namespace
}  // namespace hj
