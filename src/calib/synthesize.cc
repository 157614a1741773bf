#include "calib/synthesize.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <exception>
#include <fstream>
#include <mutex>
#include <thread>

#include "calib/frame_csv.h"
#include "calib/replay.h"

namespace hj {

namespace fs = std::filesystem;

void SynthOptions::validate() const {
  auto bad = [](const char* field, const char* why) {
    throw std::invalid_argument(std::string("synth option ") + field + " " + why);
  };
  if (!(noise_mm >= 0.0) || !std::isfinite(noise_mm)) bad("noise_mm", "(mm) must be >= 0");
  if (!(rounding_mm >= 0.0) || !std::isfinite(rounding_mm)) bad("rounding_mm", "(mm) must be >= 0");
  if (!(drop_fraction >= 0.0 && drop_fraction < 1.0)) bad("drop_fraction", "must be in [0, 1)");
  if (segments < 2 || segments > 100) bad("segments", "must be from 2 to 100");
  if (threads < 0) bad("threads", "must be >= 0 (0 = all cores)");
}

Eigen::MatrixXd add_camera_noise(const Eigen::MatrixXd& heights_mm, const SynthOptions& options, std::mt19937_64& rng) {
  std::normal_distribution<double> noise(0.0, 1.0);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  Eigen::MatrixXd out = heights_mm;
  for (int iy = 0; iy < out.rows(); ++iy)
    for (int ix = 0; ix < out.cols(); ++ix) {
      // Draw both numbers for every sample, so that a NaN does not shift the stream.
      const double n = noise(rng), u = uniform(rng);
      double& h = out(iy, ix);
      if (std::isnan(h)) continue;
      h += options.noise_mm * n;
      if (options.rounding_mm > 0.0) h = options.rounding_mm * std::round(h / options.rounding_mm);
      if (h == 0.0) h = 0.0;  // no "-0" in the files
      if (u < options.drop_fraction) h = NAN;
    }
  return out;
}

std::vector<fs::path> dataset_session_dirs(const fs::path& dataset) {
  if (!fs::is_directory(dataset)) throw SessionError(dataset.string() + ": not a dataset folder");
  std::vector<fs::path> dirs;
  for (const auto& entry : fs::directory_iterator(dataset))
    if (entry.is_directory() && fs::exists(entry.path() / "session.json")) dirs.push_back(entry.path());
  std::sort(dirs.begin(), dirs.end());
  if (dirs.empty()) throw SessionError(dataset.string() + ": holds no session folder (with a session.json)");
  return dirs;
}

namespace {

void write_text(const fs::path& path, const std::string& text) {
  std::ofstream out(path);
  out << text;
  if (!out) throw std::runtime_error(path.string() + ": cannot write");
}

std::string readme(const fs::path& dataset, const ModelParams& model, const SynthOptions& options) {
  std::string effects;
  for (const auto& name : model.effects) effects += (effects.empty() ? "" : ", ") + name;
  return "# Synthetic dataset (hapticjam synth)\n\n"
         "The sessions of `" + dataset.string() + "` replayed with the model in `truth.json`\n"
         "(hapticjam.params/1; effects: " + (effects.empty() ? "none, the baseline" : effects) + "), p = " +
         std::to_string(options.segments) + " segments per cell edge.\n\n"
         "Each capture: the settled mesh rasterised from above, plus Gaussian noise sigma = " +
         std::to_string(options.noise_mm) + " mm, rounded to " + std::to_string(options.rounding_mm) + " mm, " +
         std::to_string(100.0 * options.drop_fraction) + " % of the samples dropped (`nan`); seed " +
         std::to_string(options.seed) + ".\n";
}

}  // namespace

SynthReport synthesize_dataset(const fs::path& dataset, const fs::path& out, const ModelParams& model,
                               const SynthOptions& options, const SynthProgress& progress) {
  options.validate();
  const std::vector<fs::path> dirs = dataset_session_dirs(dataset);
  std::vector<Session> sessions;
  for (const auto& dir : dirs) sessions.push_back(read_session(dir));  // all checked before any work
  fs::create_directories(out);
  SimulatorOptions sim_options;
  model.apply_to(sim_options);

  const int total = static_cast<int>(sessions.size());
  std::atomic<int> next{0};
  std::mutex mutex;  // guards done, report, error and progress
  int done = 0;
  SynthReport report{total, 0};
  std::exception_ptr error;
  auto worker = [&] {
    for (int i = next++; i < total; i = next++) {
      try {
        const Session& session = sessions[i];
        const fs::path session_out = out / dirs[i].filename();
        const auto captures = replay_session(session, options.segments, model.surface, sim_options);
        std::seed_seq seeds{options.seed, static_cast<std::uint64_t>(i)};
        std::mt19937_64 rng(seeds);
        for (const auto& c : captures) write_frame_csv(session_out / c.frame, add_camera_noise(c.heights_mm, options, rng));
        fs::copy_file(dirs[i] / "session.json", session_out / "session.json", fs::copy_options::overwrite_existing);
        std::lock_guard lock(mutex);
        report.frames += static_cast<int>(captures.size());
        if (progress) progress(++done, total, session.name);
      } catch (...) {
        std::lock_guard lock(mutex);
        if (!error) error = std::current_exception();
        next = total;  // stop the others at their next session
      }
    }
  };
  const int threads = std::clamp(options.threads > 0 ? options.threads : static_cast<int>(std::thread::hardware_concurrency()), 1, total);
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) pool.emplace_back(worker);
  worker();
  for (auto& t : pool) t.join();
  if (error) std::rethrow_exception(error);
  write_model_params(out / "truth.json", model,
                     {{"synth", {{"source", dataset.string()}, {"noise_mm", options.noise_mm},
                                 {"rounding_mm", options.rounding_mm}, {"drop_fraction", options.drop_fraction},
                                 {"seed", options.seed}, {"segments", options.segments}}}});
  write_text(out / "README.md", readme(dataset, model, options));
  return report;
}

}  // namespace hj
