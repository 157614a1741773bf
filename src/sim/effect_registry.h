// Effects by name. Each effect file registers itself with HJ_REGISTER_EFFECT,
// so adding an effect is a one-file change; the simulator, calibration and
// diagnosis list and build effects from here.
#pragma once

#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "sim/effect.h"

namespace hj {

// A named, bounded, fittable parameter of an effect.
struct ParameterSpec {
  std::string name;  // e.g. "spring_k"
  std::string unit;  // e.g. "N/m"
  double default_value = 0.0;
  double lower = 0.0;
  double upper = 0.0;
};

// Values of one effect's parameters by ParameterSpec::name (unqualified,
// e.g. "kappa_bend"). resolve_parameters() fills in the defaults.
using EffectParameterValues = std::map<std::string, double>;

struct EffectInfo {
  std::string name;
  std::string description;
  bool baseline = false;  // part of docs/model.md's reference model
  // Parameters the effect reads. Baseline effects read theirs from
  // SurfaceParameters, named by field.
  std::vector<ParameterSpec> parameters;
  // Builds the effect with every parameter given (resolved values). Baseline
  // effects ignore the map and read SurfaceParameters.
  std::function<std::unique_ptr<Effect>(const EffectParameterValues&)> make;
  // True for an effect that only changes what the camera reports
  // (Effect::adjust_measurement): no forces, no stiffness, no state. Its
  // values then leave the simulated surfaces alone, so a calibration scan
  // over them replays the dataset once (calib/effect_scan.h). Claiming it
  // for an effect with forces makes those scans wrong.
  bool measurement_only = false;
};

// `given` completed with the defaults of `info`. Throws std::invalid_argument
// naming "effect.parameter" for an unknown name, a non-finite value or one
// outside [lower, upper] (with the bounds and unit).
EffectParameterValues resolve_parameters(const EffectInfo& info, const EffectParameterValues& given);

class EffectRegistry {
 public:
  static EffectRegistry& instance();
  // Throws std::invalid_argument on a duplicate name.
  void add(EffectInfo info);
  // Throws std::invalid_argument listing the known names on an unknown one.
  const EffectInfo& get(const std::string& name) const;
  std::vector<std::string> names() const;
  std::vector<std::string> baseline_names() const;

 private:
  std::vector<EffectInfo> effects_;
};

// The baseline model of docs/model.md, in its fixed order.
std::vector<std::unique_ptr<Effect>> make_baseline_effects();

// The baseline followed by `extra` (registry names, each at most once), each
// built with its entry of `values` (effect name -> parameter values; missing
// parameters take their defaults). Throws std::invalid_argument for an
// unknown or repeated effect, values for an effect not in `extra`, or a bad
// value (see resolve_parameters).
std::vector<std::unique_ptr<Effect>> make_effects(const std::vector<std::string>& extra,
                                                  const std::map<std::string, EffectParameterValues>& values);

namespace detail {
struct EffectRegistration {
  explicit EffectRegistration(EffectInfo info) { EffectRegistry::instance().add(std::move(info)); }
};
}  // namespace detail

}  // namespace hj

#define HJ_REGISTER_EFFECT_CONCAT2(a, b) a##b
#define HJ_REGISTER_EFFECT_CONCAT(a, b) HJ_REGISTER_EFFECT_CONCAT2(a, b)
// In an effect's .cc file: HJ_REGISTER_EFFECT(EffectInfo{...});
#define HJ_REGISTER_EFFECT(...)                                                                  \
  static const ::hj::detail::EffectRegistration HJ_REGISTER_EFFECT_CONCAT(hj_effect_registration_, \
                                                                           __LINE__)(__VA_ARGS__)
