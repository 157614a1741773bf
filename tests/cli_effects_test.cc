// The model options of the CLI (--params, --effects, --set) and `synth`:
// the same model given three ways predicts the same frames, bad values exit
// with a message naming the parameter, and a synthetic dataset is the exact
// prediction plus seeded camera noise as the shared datasets describe it.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>

#include "calib/frame_csv.h"
#include "calib/model_params.h"
#include "calib/synthesize.h"
#include "cli_runner.h"
#include "expect_error.h"
#include "scratch_dir.h"

namespace hj {
namespace {

namespace fs = std::filesystem;
using testing_support::quoted;
using testing_support::read_text;
using testing_support::run_cli;
using testing_support::ScratchDir;

// A small session (1 x 2 cells) with two captures.
void write_small_session(const fs::path& dir, double kpa) {
  fs::create_directories(dir);
  std::ofstream(dir / "session.json") << R"({
    "format": "hapticjam.session/1", "name": ")" << dir.filename().string() << R"(",
    "device": {"rows": 1, "cols": 2, "cell_size_mm": 38.0, "max_pressure_kpa": 3.45},
    "grid": {"nx": 39, "ny": 20, "x0_mm": 0.0, "y0_mm": 0.0, "dx_mm": 2.0, "dy_mm": 2.0},
    "steps": [{"op": "capture", "frame": "frames/000.csv"}, {"op": "set_pressure", "kpa": )"
                                      << kpa << R"(}, {"op": "jam", "cell": [0, 1]},
              {"op": "capture", "frame": "frames/001.csv"}]})";
}

double max_abs_difference(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  double m = 0.0;
  for (int i = 0; i < a.size(); ++i) {
    EXPECT_EQ(std::isnan(a(i)), std::isnan(b(i)));
    if (!std::isnan(a(i))) m = std::max(m, std::abs(a(i) - b(i)));
  }
  return m;
}

Eigen::MatrixXd frame(const fs::path& path) { return read_frame_csv(path, 20, 39); }

TEST(CliModelOptions, ParamsFileEffectsAndSetGiveTheSameModel) {
  ScratchDir dir;
  write_small_session(dir.path / "s", 1.5);
  std::ofstream(dir.path / "p.json") << R"({"format": "hapticjam.params/1", "surface": {"spring_k": 58},
                                           "effects": {"bending": {"kappa_bend": 0.01}}})";
  const std::string session = quoted(dir.path / "s" / "session.json");
  ASSERT_EQ(run_cli("simulate " + session + " --out " + quoted(dir.path / "a") + " --params " + quoted(dir.path / "p.json"),
                    dir.path), 0) << read_text(dir.path / "stderr.txt");
  EXPECT_NE(read_text(dir.path / "stdout.txt").find("effects on: bending"), std::string::npos);
  ASSERT_EQ(run_cli("simulate " + session + " --out " + quoted(dir.path / "b") +
                        " --effects bending --set bending.kappa_bend=0.01 --set surface.spring_k=58", dir.path), 0)
      << read_text(dir.path / "stderr.txt");
  ASSERT_EQ(run_cli("simulate " + session + " --out " + quoted(dir.path / "c") + " --k 58", dir.path), 0);
  const Eigen::MatrixXd a = frame(dir.path / "a/frames/001.csv"), b = frame(dir.path / "b/frames/001.csv");
  EXPECT_EQ(max_abs_difference(a, b), 0.0);
  EXPECT_GT(max_abs_difference(a, frame(dir.path / "c/frames/001.csv")), 0.1) << "mm: bending changes the bulge";
}

TEST(CliModelOptions, BadValuesNameTheParameter) {
  ScratchDir dir;
  write_small_session(dir.path / "s", 1.0);
  const std::string simulate = "simulate " + quoted(dir.path / "s" / "session.json") + " --out " + quoted(dir.path / "o");
  EXPECT_EQ(run_cli(simulate + " --set bending.kappa_bend=7", dir.path), 1);
  std::string err = read_text(dir.path / "stderr.txt");
  EXPECT_NE(err.find("bending.kappa_bend"), std::string::npos) << err;
  EXPECT_NE(err.find("[0, 1] N m/rad"), std::string::npos) << err;
  EXPECT_EQ(run_cli(simulate + " --effects bendng", dir.path), 1);
  EXPECT_NE(read_text(dir.path / "stderr.txt").find("known effects"), std::string::npos);
  EXPECT_EQ(run_cli(simulate + " --set surface.spring=3", dir.path), 1);
  EXPECT_NE(read_text(dir.path / "stderr.txt").find("surface.spring"), std::string::npos);
  EXPECT_EQ(run_cli(simulate + " --set kappa_bend=0.1", dir.path), 2) << "not effect.parameter: a usage error";
  EXPECT_EQ(run_cli(simulate + " --set bending.kappa_bend=abc", dir.path), 2);
  EXPECT_FALSE(fs::exists(dir.path / "o" / "frames"));
}

TEST(Synth, WritesTheExactPredictionWithoutNoiseAndSeededNoiseWithIt) {
  ScratchDir dir;
  write_small_session(dir.path / "in" / "one", 1.0);
  write_small_session(dir.path / "in" / "two", 2.0);
  const std::string model = " --set stiffening.beta=30 --set sensor_tilt.offset_mm=2";
  ASSERT_EQ(run_cli("synth " + quoted(dir.path / "in") + " --out " + quoted(dir.path / "exact") + model +
                        " --noise-mm 0 --round-mm 0 --drop 0", dir.path), 0)
      << read_text(dir.path / "stderr.txt");
  ASSERT_EQ(run_cli("simulate " + quoted(dir.path / "in/two/session.json") + " --out " + quoted(dir.path / "sim") + model,
                    dir.path), 0);
  EXPECT_LT(max_abs_difference(frame(dir.path / "exact/two/frames/001.csv"), frame(dir.path / "sim/frames/001.csv")),
            1e-9);
  EXPECT_TRUE(fs::exists(dir.path / "exact/one/session.json"));
  const ModelParams truth = read_model_params(dir.path / "exact/truth.json", SurfaceParameters{});
  ASSERT_EQ(truth.effects.size(), 2u);
  EXPECT_EQ(truth.effect_parameters.at("stiffening").at("beta"), 30.0);

  for (const char* run : {"n1", "n2"})
    ASSERT_EQ(run_cli("synth " + quoted(dir.path / "in") + " --out " + quoted(dir.path / run) + model + " --seed 5",
                      dir.path), 0);
  ASSERT_EQ(run_cli("synth " + quoted(dir.path / "in") + " --out " + quoted(dir.path / "n3") + model + " --seed 6",
                    dir.path), 0);
  const std::string f = "two/frames/001.csv";
  EXPECT_EQ(read_text(dir.path / "n1" / f), read_text(dir.path / "n2" / f)) << "the same seed, the same frames";
  EXPECT_NE(read_text(dir.path / "n1" / f), read_text(dir.path / "n3" / f));
}

TEST(Synth, CameraNoiseHasTheStatedSigmaRoundingAndDrops) {
  Eigen::MatrixXd exact(200, 200);
  for (int i = 0; i < exact.size(); ++i) exact(i) = 0.01 * (i % 997) - 3.3;
  exact(5) = NAN;
  SynthOptions options;  // 1 mm noise, rounded to 1 mm, 1 % dropped
  std::mt19937_64 rng(3);
  const Eigen::MatrixXd seen = add_camera_noise(exact, options, rng);
  EXPECT_TRUE(std::isnan(seen(5))) << "unseen stays unseen";
  int dropped = 0, n = 0;
  double sum = 0.0, sum2 = 0.0;
  for (int i = 0; i < seen.size(); ++i) {
    if (i == 5) continue;
    if (std::isnan(seen(i))) {
      ++dropped;
      continue;
    }
    EXPECT_EQ(seen(i), std::round(seen(i))) << "rounded to 1 mm";
    const double e = seen(i) - exact(i);
    sum += e, sum2 += e * e, ++n;
  }
  EXPECT_NEAR(static_cast<double>(dropped) / (seen.size() - 1), 0.01, 0.002);
  EXPECT_NEAR(sum / n, 0.0, 0.02);
  // Gaussian sigma 1 plus rounding (uniform, variance 1/12): 1.04 mm rms, as the shared READMEs say.
  EXPECT_NEAR(std::sqrt(sum2 / n), std::sqrt(1.0 + 1.0 / 12.0), 0.02);
}

TEST(Synth, BadInputIsNamed) {
  ScratchDir dir;
  testing_support::expect_error<SessionError>(
      [&] { (void)dataset_session_dirs(dir.path); }, {dir.path.string(), "no session folder"});
  EXPECT_EQ(run_cli("synth " + quoted(dir.path) + " --out " + quoted(dir.path / "o") + " --drop 1.5", dir.path), 2);
  EXPECT_NE(read_text(dir.path / "stderr.txt").find("drop_fraction"), std::string::npos);
}

}  // namespace
}  // namespace hj
