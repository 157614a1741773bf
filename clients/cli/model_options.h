// The model options every command that simulates takes: a params file
// (calib/model_params.h), more effects, and single values, merged in that
// order into one ModelParams:
//   --params FILE               hapticjam.params/1 (e.g. a fit's params.json)
//   --effects a,b               switch effects on (registry names), at defaults
//   --set effect.param=VALUE    one effect parameter (switches the effect on)
//   --set surface.field=VALUE   one baseline field (mass_kg, spring_k, ...)
#pragma once

#include <string>
#include <vector>

#include "args.h"
#include "calib/model_params.h"

namespace hj::cli {

struct ModelOptions {
  std::string params_file;
  std::vector<std::string> effects;
  std::vector<std::pair<std::string, double>> sets;  // "effect.param" or "surface.field" -> value

  // Consumes the option at `cursor` if it is one of the above; false if not.
  // Throws std::invalid_argument naming the option on a malformed value.
  bool parse(ArgCursor& cursor);

  // The merged model, `defaults` supplying what nothing sets. Throws
  // ParamsError naming the file or option and the key that is wrong.
  ModelParams resolve(const SurfaceParameters& defaults) const;
};

inline constexpr const char* kModelOptionsUsage =
    "  --params FILE        model parameters and effects (hapticjam.params/1, e.g. a fit's params.json)\n"
    "  --effects A,B        switch optional effects on at their defaults (see src/sim/effects/README.md)\n"
    "  --set NAME=VALUE     one value: effect.parameter (switches the effect on) or surface.field\n";

}  // namespace hj::cli
