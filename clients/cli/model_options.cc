#include "model_options.h"

#include <sstream>
#include <stdexcept>

namespace hj::cli {

bool ModelOptions::parse(ArgCursor& cursor) {
  const std::string& a = cursor.arg();
  if (a == "--params") {
    params_file = cursor.value();
  } else if (a == "--effects") {
    std::stringstream list(cursor.value());
    for (std::string name; std::getline(list, name, ',');)
      if (!name.empty()) effects.push_back(name);
  } else if (a == "--set") {
    const std::string& text = cursor.value();
    const auto eq = text.find('='), dot = text.find('.');
    if (eq == std::string::npos || dot == std::string::npos || dot > eq || dot == 0 || dot + 1 == eq)
      throw std::invalid_argument("--set needs effect.parameter=value or surface.field=value, got \"" + text + "\"");
    sets.emplace_back(text.substr(0, eq), parse_number("--set " + text.substr(0, eq), text.substr(eq + 1)));
  } else {
    return false;
  }
  return true;
}

ModelParams ModelOptions::resolve(const SurfaceParameters& defaults) const {
  ModelParams base;
  base.surface = defaults;
  if (!params_file.empty()) base = read_model_params(params_file, defaults);
  if (effects.empty() && sets.empty()) return base;
  // Merge as a params document so that one parser checks every name and bound.
  nlohmann::json doc = model_params_json(base);
  for (const auto& name : effects)
    if (!doc["effects"].contains(name)) doc["effects"][name] = nlohmann::json::object();
  for (const auto& [key, value] : sets) {
    const auto dot = key.find('.');
    const std::string group = key.substr(0, dot), field = key.substr(dot + 1);
    if (group == "surface")
      doc["surface"][field] = value;
    else
      doc["effects"][group][field] = value;
  }
  return parse_model_params(doc, defaults, "the command line (--params, --effects, --set)");
}

}  // namespace hj::cli
