// A model to simulate with, as a file: the baseline parameters plus the
// optional effects that are switched on and their parameter values. `fit`
// writes it (DIR/params.json), and every command's --params reads it.
//
//   {"format": "hapticjam.params/1",
//    "surface": {"mass_kg": 0.52, "spring_k": 58, "kappa_jam": 4.2},
//    "effects": {"bending": {"kappa_bend": 0.002}}, ...}
//
// "surface" keys are SurfaceParameters fields (mass_kg, spring_k, damping_b,
// kappa_jam, gravity, max_pressure_pa); a missing one keeps its default. Each
// key of "effects" switches that effect on; a missing parameter takes the
// registry default. Other top-level keys (a fit's uncertainties, r^2 ...)
// are kept for people and ignored here.
#pragma once

#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "sim/effect_registry.h"
#include "sim/simulator.h"

namespace hj {

class ParamsError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct ModelParams {
  SurfaceParameters surface;
  std::vector<std::string> effects;                                // switched on, in file order
  std::map<std::string, EffectParameterValues> effect_parameters;  // resolved: every parameter present

  // Copies the effects and their values into `options`.
  void apply_to(SimulatorOptions& options) const;
};

// The reverse of apply_to: `surface` with the effects `options` switches
// on, every parameter value resolved (missing = the effect's default).
ModelParams model_params_of(const SurfaceParameters& surface, const SimulatorOptions& options);

// The SurfaceParameters field named `name` (mass_kg, spring_k, damping_b,
// kappa_jam, gravity, max_pressure_pa), or nullptr for another name.
double* surface_field(SurfaceParameters& surface, const std::string& name);

// Parses a params document; `defaults` supplies the surface fields it omits.
// @throws ParamsError naming `origin` (a file name) and the key that is
//         wrong: not an object, an unknown surface field or effect, a value
//         that is not a number or is out of bounds.
ModelParams parse_model_params(const nlohmann::json& doc, const SurfaceParameters& defaults,
                               const std::string& origin);
ModelParams read_model_params(const std::filesystem::path& path, const SurfaceParameters& defaults);

// The document for `params`, with `extra` merged in at the top level.
nlohmann::json model_params_json(const ModelParams& params, const nlohmann::json& extra = nlohmann::json::object());
// Writes it atomically (temporary file, then rename).
// @throws std::runtime_error naming the file if it cannot be written.
void write_model_params(const std::filesystem::path& path, const ModelParams& params,
                        const nlohmann::json& extra = nlohmann::json::object());

}  // namespace hj
