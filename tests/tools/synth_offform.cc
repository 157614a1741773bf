// synth_offform DATASET --out DIR --params FILE [--threads N]: `hapticjam
// synth` with the test-only effects of offform_effects.cc registered too,
// so that scripts/synth_effects.sh can make datasets whose effect differs
// in form from every diagnose candidate (its camera: 1 mm noise, rounded to
// 1 mm, 1 % dropped, seed 1, as `hapticjam synth`'s defaults).
#include <cstdio>
#include <exception>
#include <string>

#include "calib/dataset.h"
#include "calib/model_params.h"
#include "calib/session.h"
#include "calib/synthesize.h"

int main(int argc, char** argv) {
  std::string dataset, out, params;
  int threads = 0;
  for (int k = 1; k < argc; ++k) {
    const std::string a = argv[k];
    const bool has_value = k + 1 < argc;
    if (a == "--out" && has_value) out = argv[++k];
    else if (a == "--params" && has_value) params = argv[++k];
    else if (a == "--threads" && has_value) threads = std::stoi(argv[++k]);
    else if (dataset.empty() && a[0] != '-') dataset = a;
    else {
      std::fprintf(stderr, "synth_offform: unexpected argument %s\n", a.c_str());
      return 2;
    }
  }
  if (dataset.empty() || out.empty() || params.empty()) {
    std::fprintf(stderr, "usage: synth_offform DATASET --out DIR --params FILE [--threads N]\n");
    return 2;
  }
  try {
    const hj::Session first = hj::read_session(hj::dataset_session_dirs(dataset).front());
    const hj::ModelParams model =
        hj::read_model_params(params, hj::SurfaceParameters::paper_defaults(first.device.geometry()));
    hj::SynthOptions options;
    options.threads = threads;
    const hj::SynthReport report = hj::synthesize_dataset(dataset, out, model, options);
    std::printf("%d sessions, %d frames written to %s\n", report.sessions, report.frames, out.c_str());
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "synth_offform: %s\n", e.what());
    return 1;
  }
}
