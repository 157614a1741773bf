#include "sim/effect_registry.h"

#include <algorithm>
#include <stdexcept>

namespace hj {

EffectRegistry& EffectRegistry::instance() {
  static EffectRegistry registry;
  return registry;
}

void EffectRegistry::add(EffectInfo info) {
  for (const auto& e : effects_)
    if (e.name == info.name) throw std::invalid_argument("effect \"" + info.name + "\" is registered twice");
  effects_.push_back(std::move(info));
}

const EffectInfo& EffectRegistry::get(const std::string& name) const {
  for (const auto& e : effects_)
    if (e.name == name) return e;
  std::string known;
  for (const auto& n : names()) known += (known.empty() ? "" : ", ") + n;
  throw std::invalid_argument("unknown effect \"" + name + "\"; known effects: " + known);
}

std::vector<std::string> EffectRegistry::names() const {
  std::vector<std::string> out;
  for (const auto& e : effects_) out.push_back(e.name);
  std::sort(out.begin(), out.end());
  return out;
}

std::vector<std::string> EffectRegistry::baseline_names() const {
  std::vector<std::string> out;
  for (const auto& e : effects_)
    if (e.baseline) out.push_back(e.name);
  return out;
}

std::vector<std::unique_ptr<Effect>> make_baseline_effects() {
  std::vector<std::unique_ptr<Effect>> effects;
  for (const char* name : {"springs", "gravity", "pressure", "jamming"})
    effects.push_back(EffectRegistry::instance().get(name).make());
  return effects;
}

}  // namespace hj
