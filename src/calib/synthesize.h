// Synthetic datasets: every session of a dataset replayed with a chosen
// model (baseline + effects), each capture seen by a simulated depth camera
// as in the shared datasets' READMEs: Gaussian noise, rounding to the
// camera's resolution, a share of samples dropped. One dataset per effect
// lets the calibration tools be tested on data whose truth is known.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "calib/model_params.h"
#include "calib/session.h"

namespace hj {

struct SynthOptions {
  double noise_mm = 1.0;        // sigma of the Gaussian camera noise
  double rounding_mm = 1.0;     // heights rounded to this (0: not rounded)
  double drop_fraction = 0.01;  // share of samples written as nan
  std::uint64_t seed = 1;       // noise of session i is seeded by (seed, i)
  int segments = 4;             // p of the simulated mesh
  int threads = 0;              // sessions replayed at once; 0 = all cores

  // Throws std::invalid_argument naming the bad field.
  void validate() const;
};

// The camera's view of exact heights (ny x nx, mm): + N(0, noise), rounded,
// a drop_fraction of samples set to NaN; NaN stays NaN.
Eigen::MatrixXd add_camera_noise(const Eigen::MatrixXd& heights_mm, const SynthOptions& options, std::mt19937_64& rng);

// The session folders of a dataset (sub-folders holding session.json), by name.
// @throws SessionError naming the folder if it is not one or holds none.
std::vector<std::filesystem::path> dataset_session_dirs(const std::filesystem::path& dataset);

struct SynthReport {
  int sessions = 0;
  int frames = 0;
};

// Called as each session finishes: sessions done, in all, and its name.
using SynthProgress = std::function<void(int done, int total, const std::string& session)>;

// Writes out/<session>/session.json (a copy) and its frames for every
// session of `dataset`, plus out/truth.json (the model, hapticjam.params/1,
// with the camera settings) and out/README.md. Sessions run in parallel.
// @throws SessionError / std::runtime_error naming the session, step or
//         file on a bad session, a failed settle or an unwritable file.
SynthReport synthesize_dataset(const std::filesystem::path& dataset, const std::filesystem::path& out,
                               const ModelParams& model, const SynthOptions& options,
                               const SynthProgress& progress = {});

}  // namespace hj
