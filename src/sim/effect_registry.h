// Effects by name. Each effect file registers itself with HJ_REGISTER_EFFECT,
// so adding an effect is a one-file change; the simulator, calibration and
// diagnosis list and build effects from here.
#pragma once

#include <functional>
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

struct EffectInfo {
  std::string name;
  std::string description;
  bool baseline = false;  // part of docs/model.md's reference model
  // Parameters the effect reads. Baseline effects read theirs from
  // SurfaceParameters, named by field.
  std::vector<ParameterSpec> parameters;
  std::function<std::unique_ptr<Effect>()> make;
};

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
