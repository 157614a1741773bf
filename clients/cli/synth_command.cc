#include "synth_command.h"

#include <chrono>
#include <cstdio>

#include "args.h"
#include "calib/synthesize.h"
#include "model_options.h"
#include "progress.h"

namespace hj::cli {

namespace {

const std::string kSynthUsage = std::string(
    "usage: hapticjam synth DATASET --out DIR [--params FILE] [--effects A,B] [--set NAME=VALUE]\n"
    "                       [--noise-mm SIGMA] [--round-mm STEP] [--drop FRACTION] [--seed N]\n"
    "                       [--segments P] [--threads N]\n"
    "Replays every session of DATASET (a folder of session folders) with the given model and\n"
    "writes a synthetic dataset to DIR: each session's session.json and its frames as a depth\n"
    "camera would see them, plus DIR/truth.json (the model, loadable by --params) and README.md.\n"
    "The model is the paper's baseline unless --params/--effects/--set change it:\n") +
                                kModelOptionsUsage +
                                "  --noise-mm SIGMA     Gaussian camera noise (default 1 mm)\n"
                                "  --round-mm STEP      round heights to STEP (default 1 mm, 0 = off)\n"
                                "  --drop FRACTION      share of samples written as nan (default 0.01)\n"
                                "  --seed N             noise seed (default 1)\n"
                                "  --segments P         segments per cell edge (default 4)\n"
                                "  --threads N          sessions at once (default: all cores)\n";

struct SynthArgs {
  std::string dataset, out;
  ModelOptions model;
  SynthOptions synth;
};

SynthArgs parse_synth_args(const std::vector<std::string>& args) {
  SynthArgs out;
  for (ArgCursor cursor(args); cursor.next();) {
    const std::string& a = cursor.arg();
    if (a == "--out") out.out = cursor.value();
    else if (a == "--noise-mm") out.synth.noise_mm = parse_number(a, cursor.value());
    else if (a == "--round-mm") out.synth.rounding_mm = parse_number(a, cursor.value());
    else if (a == "--drop") out.synth.drop_fraction = parse_number(a, cursor.value());
    else if (a == "--seed") out.synth.seed = static_cast<std::uint64_t>(parse_int(a, cursor.value(), 0, 2'000'000'000));
    else if (a == "--segments") out.synth.segments = parse_int(a, cursor.value(), 2, 100);
    else if (a == "--threads") out.synth.threads = parse_int(a, cursor.value(), 0, 1024);
    else if (out.model.parse(cursor)) continue;
    else if (!a.empty() && a[0] == '-') throw std::invalid_argument("unknown option " + a);
    else if (out.dataset.empty()) out.dataset = a;
    else throw std::invalid_argument("unexpected argument \"" + a + "\"");
  }
  if (out.dataset.empty()) throw std::invalid_argument("missing DATASET");
  if (out.out.empty()) throw std::invalid_argument("missing --out DIR");
  out.synth.validate();
  return out;
}

int synth(const SynthArgs& args) {
  const auto start = std::chrono::steady_clock::now();
  // The paper's defaults for the dataset's device (one device per dataset,
  // docs/session-format.md), as simulate takes them.
  const Session first = read_session(dataset_session_dirs(args.dataset).front());
  const ModelParams model = args.model.resolve(SurfaceParameters::paper_defaults(first.device.geometry()));
  ProgressLine progress("synth " + args.dataset);
  const SynthReport report = synthesize_dataset(args.dataset, args.out, model, args.synth,
                                                [&](int done, int total, const std::string& name) {
                                                  progress.update(done, total, name);
                                                });
  progress.finish();
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("%d sessions, %d frames written to %s in %.1f s (model in %s/truth.json)\n", report.sessions,
              report.frames, args.out.c_str(), seconds, args.out.c_str());
  return 0;
}

}  // namespace

int run_synth(const std::vector<std::string>& args) {
  return run_subcommand<SynthArgs>("synth", kSynthUsage.c_str(), args, parse_synth_args, synth);
}

}  // namespace hj::cli
