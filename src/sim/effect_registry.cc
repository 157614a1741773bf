#include "sim/effect_registry.h"

#include <algorithm>
#include <cmath>
#include <set>
#include <sstream>
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

EffectParameterValues resolve_parameters(const EffectInfo& info, const EffectParameterValues& given) {
  EffectParameterValues out;
  for (const auto& spec : info.parameters) out[spec.name] = spec.default_value;
  for (const auto& [name, value] : given) {
    const auto spec = std::find_if(info.parameters.begin(), info.parameters.end(),
                                   [&name = name](const ParameterSpec& s) { return s.name == name; });
    if (spec == info.parameters.end()) {
      std::string known;
      for (const auto& s : info.parameters) known += (known.empty() ? "" : ", ") + s.name;
      throw std::invalid_argument("unknown parameter \"" + info.name + "." + name + "\"; " + info.name +
                                  (known.empty() ? " has no parameters" : " has: " + known));
    }
    if (!std::isfinite(value) || value < spec->lower || value > spec->upper) {
      std::ostringstream msg;
      msg << "parameter " << info.name << "." << name << " = " << value << " " << spec->unit << " is outside ["
          << spec->lower << ", " << spec->upper << "] " << spec->unit;
      throw std::invalid_argument(msg.str());
    }
    out[name] = value;
  }
  return out;
}

std::vector<std::unique_ptr<Effect>> make_baseline_effects() { return make_effects({}, {}); }

std::vector<std::unique_ptr<Effect>> make_effects(const std::vector<std::string>& extra,
                                                  const std::map<std::string, EffectParameterValues>& values) {
  const auto& registry = EffectRegistry::instance();
  std::vector<std::string> names = {"springs", "gravity", "pressure", "jamming"};
  std::set<std::string> seen(names.begin(), names.end());
  for (const auto& name : extra) {
    if (!seen.insert(name).second) throw std::invalid_argument("effect \"" + name + "\" is listed twice");
    names.push_back(name);
  }
  for (const auto& [name, unused] : values)
    if (!seen.count(name))
      throw std::invalid_argument("parameters given for effect \"" + name + "\", which is not switched on");
  std::vector<std::unique_ptr<Effect>> effects;
  for (const auto& name : names) {
    const EffectInfo& info = registry.get(name);
    const auto given = values.find(name);
    effects.push_back(info.make(resolve_parameters(info, given == values.end() ? EffectParameterValues{} : given->second)));
  }
  return effects;
}

}  // namespace hj
