// The measurement commands of the CLI (compare, fit, diagnose) on a small
// dataset made of two demo-baseline sessions: their JSON has the documented
// keys, the report is self-contained, fit's params.json loads with --params,
// and bad input exits non-zero naming what is wrong.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "calib/model_params.h"
#include "scratch_dir.h"

namespace hj {
namespace {

namespace fs = std::filesystem;
using testing_support::ScratchDir;

const fs::path kBaseline = fs::path(HJ_SHARED_DIR) / "data/sessions/demo-baseline";

std::string quoted(const fs::path& p) { return "'" + p.string() + "'"; }

int run_cli(const std::string& args, const fs::path& dir) {
  const std::string command = quoted(HJ_CLI_PATH) + " " + args + " >" + quoted(dir / "stdout.txt") + " 2>" +
                              quoted(dir / "stderr.txt");
  const int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

std::string read_text(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

nlohmann::json read_json(const fs::path& p) { return nlohmann::json::parse(read_text(p)); }

// A dataset of two cheap sessions (no jammed sweep).
fs::path small_dataset(const fs::path& dir) {
  const fs::path out = dir / "dataset";
  fs::create_directories(out);
  for (const char* name : {"unjammed-sweep", "mixed-1"})
    fs::copy(kBaseline / name, out / name, fs::copy_options::recursive);
  return out;
}

void expect_self_contained(const fs::path& html) {
  const std::string text = read_text(html);
  ASSERT_FALSE(text.empty()) << html;
  EXPECT_EQ(text.find("src='http"), std::string::npos);
  EXPECT_EQ(text.find("src=\"http"), std::string::npos);
  EXPECT_EQ(text.find("<link"), std::string::npos);
  EXPECT_EQ(text.find("<script"), std::string::npos);
}

TEST(CalibCli, CompareWritesTheSummaryHeatMapsAndReport) {
  ScratchDir dir;
  const fs::path dataset = small_dataset(dir.path);
  const fs::path params = dir.path / "true.json";
  std::ofstream(params) << R"({"surface": {"mass_kg": 0.52, "spring_k": 58, "kappa_jam": 4.2}})";
  const fs::path out = dir.path / "cmp";
  ASSERT_EQ(run_cli("compare " + quoted(dataset) + " --params " + quoted(params) + " --out " + quoted(out), dir.path), 0)
      << read_text(dir.path / "stderr.txt");
  const auto summary = read_json(out / "summary.json");
  for (const char* key : {"rmse_mm", "mae_mm", "sessions", "cells"}) EXPECT_TRUE(summary.contains(key)) << key;
  // The true model leaves the camera's noise: about 1.04 mm RMSE, 0.83 mm mean absolute.
  EXPECT_NEAR(summary["rmse_mm"].get<double>(), 1.04, 0.05);
  EXPECT_NEAR(summary["mae_mm"].get<double>(), 0.83, 0.05);
  ASSERT_EQ(summary["sessions"].size(), 2u);
  EXPECT_EQ(summary["sessions"][0]["name"], "mixed-1");
  ASSERT_EQ(summary["sessions"][0]["captures"].size(), 4u);
  for (const auto& s : summary["sessions"])
    for (const auto& c : s["captures"]) {
      for (const char* key : {"frame", "rmse_mm", "mae_mm", "max_mm"}) EXPECT_TRUE(c.contains(key)) << key;
      EXPECT_GE(c["max_mm"].get<double>(), c["rmse_mm"].get<double>());
      EXPECT_TRUE(fs::exists(out / c["image"].get<std::string>())) << c["image"];
    }
  ASSERT_EQ(summary["cells"].size(), 12u);
  EXPECT_EQ(summary["cells"][5]["cell"], nlohmann::json({1, 1}));
  expect_self_contained(out / "report.html");
}

TEST(CalibCli, FitWritesLoadableParamsWithUncertaintiesAndHeldOutError) {
  ScratchDir dir;
  const fs::path dataset = small_dataset(dir.path);
  const fs::path out = dir.path / "fit";
  ASSERT_EQ(run_cli("fit " + quoted(dataset) + " --holdout mixed-1 --max-iterations 8 --out " + quoted(out), dir.path),
            0)
      << read_text(dir.path / "stderr.txt");
  const auto doc = read_json(out / "params.json");
  EXPECT_EQ(doc["format"], "hapticjam.params/1");
  for (const char* key : {"uncertainties", "r2", "rmse_mm", "heldout", "levelling", "algorithm1"})
    EXPECT_TRUE(doc.contains(key)) << key;
  EXPECT_TRUE(doc["uncertainties"]["spring_k"].contains("ci95"));
  EXPECT_TRUE(doc["heldout"].contains("rmse_mm"));
  EXPECT_LT(doc["heldout"]["rmse_mm"].get<double>(), 1.2);
  // The notes name the parameter the data pin down least, whether or not
  // it is flagged loose.
  bool least = false;
  for (const auto& note : doc["notes"]) least = least || note.get<std::string>().find("is the least constrained parameter") != std::string::npos;
  EXPECT_TRUE(least) << doc["notes"].dump();
  const ModelParams loaded = read_model_params(out / "params.json", SurfaceParameters{});
  EXPECT_NEAR(loaded.surface.spring_k, 58.0, 0.03 * 58.0);
  expect_self_contained(out / "report.html");
  // Every command takes it back with --params.
  ASSERT_EQ(run_cli("compare " + quoted(dataset) + " --params " + quoted(out / "params.json") + " --out " +
                        quoted(dir.path / "cmp"),
                    dir.path),
            0)
      << read_text(dir.path / "stderr.txt");
  EXPECT_LT(read_json(dir.path / "cmp" / "summary.json")["rmse_mm"].get<double>(), 1.1);
}

TEST(CalibCli, BadInputExitsNamingWhatIsWrong) {
  ScratchDir dir;
  EXPECT_EQ(run_cli("compare " + quoted(dir.path) + " --out " + quoted(dir.path / "x"), dir.path), 1);
  EXPECT_NE(read_text(dir.path / "stderr.txt").find("no session folders"), std::string::npos);
  EXPECT_EQ(run_cli("fit " + quoted(kBaseline) + " --effects no_such_effect --out " + quoted(dir.path / "x"), dir.path), 2);
  EXPECT_NE(read_text(dir.path / "stderr.txt").find("no_such_effect"), std::string::npos);
  EXPECT_EQ(run_cli("fit " + quoted(kBaseline) + " --holdout nope --out " + quoted(dir.path / "x"), dir.path), 1);
  EXPECT_NE(read_text(dir.path / "stderr.txt").find("nope"), std::string::npos);
  EXPECT_EQ(run_cli("diagnose " + quoted(kBaseline), dir.path), 2);
  EXPECT_NE(read_text(dir.path / "stderr.txt").find("--out"), std::string::npos);
  const fs::path bad_params = dir.path / "bad.json";
  std::ofstream(bad_params) << R"({"surface": {"spring_k": "stiff"}})";
  EXPECT_EQ(run_cli("compare " + quoted(kBaseline) + " --params " + quoted(bad_params) + " --out " +
                        quoted(dir.path / "x"),
                    dir.path),
            1);
  EXPECT_NE(read_text(dir.path / "stderr.txt").find("surface.spring_k"), std::string::npos);
}

}  // namespace
}  // namespace hj
