#include "calib/model_params.h"

#include <fstream>
#include <sstream>

namespace hj {

namespace {

constexpr const char* kFormat = "hapticjam.params/1";

struct SurfaceField {
  const char* name;
  double SurfaceParameters::*member;
};
constexpr SurfaceField kSurfaceFields[] = {
    {"mass_kg", &SurfaceParameters::mass_kg},     {"spring_k", &SurfaceParameters::spring_k},
    {"damping_b", &SurfaceParameters::damping_b}, {"kappa_jam", &SurfaceParameters::kappa_jam},
    {"gravity", &SurfaceParameters::gravity},     {"max_pressure_pa", &SurfaceParameters::max_pressure_pa},
};

[[noreturn]] void fail(const std::string& origin, const std::string& key, const std::string& what) {
  throw ParamsError(origin + ": " + (key.empty() ? "" : "\"" + key + "\": ") + what);
}

double number(const nlohmann::json& v, const std::string& origin, const std::string& key) {
  if (!v.is_number()) fail(origin, key, "must be a number, got " + v.dump());
  return v.get<double>();
}

}  // namespace

double* surface_field(SurfaceParameters& surface, const std::string& name) {
  for (const auto& f : kSurfaceFields)
    if (name == f.name) return &(surface.*(f.member));
  return nullptr;
}

void ModelParams::apply_to(SimulatorOptions& options) const {
  options.extra_effects = effects;
  options.effect_parameters = effect_parameters;
}

ModelParams parse_model_params(const nlohmann::json& doc, const SurfaceParameters& defaults,
                               const std::string& origin) {
  if (!doc.is_object()) fail(origin, "", "a params file must be a JSON object");
  if (doc.contains("format") && doc["format"] != kFormat)
    fail(origin, "format", "expected \"" + std::string(kFormat) + "\", got " + doc["format"].dump());
  ModelParams out;
  out.surface = defaults;
  if (doc.contains("surface")) {
    const auto& surface = doc["surface"];
    if (!surface.is_object()) fail(origin, "surface", "must be an object");
    for (const auto& [key, value] : surface.items()) {
      const SurfaceField* field = nullptr;
      for (const auto& f : kSurfaceFields)
        if (key == f.name) field = &f;
      if (!field) {
        std::string known;
        for (const auto& f : kSurfaceFields) known += (known.empty() ? "" : ", ") + std::string(f.name);
        fail(origin, "surface." + key, "unknown field; known: " + known);
      }
      out.surface.*(field->member) = number(value, origin, "surface." + key);
    }
  }
  try {
    out.surface.validate();
  } catch (const std::invalid_argument& e) {
    fail(origin, "surface", e.what());
  }
  if (doc.contains("effects")) {
    const auto& effects = doc["effects"];
    if (!effects.is_object()) fail(origin, "effects", "must be an object of effect name -> {parameter: value}");
    for (const auto& [name, values] : effects.items()) {
      const std::string key = "effects." + name;
      if (!values.is_object()) fail(origin, key, "must be an object of parameter -> value");
      EffectParameterValues given;
      for (const auto& [param, value] : values.items()) given[param] = number(value, origin, key + "." + param);
      try {
        const EffectInfo& info = EffectRegistry::instance().get(name);
        if (info.baseline) fail(origin, key, "is part of the baseline model; set its values under \"surface\"");
        out.effect_parameters[name] = resolve_parameters(info, given);
      } catch (const std::invalid_argument& e) {
        fail(origin, key, e.what());
      }
      out.effects.push_back(name);
    }
  }
  return out;
}

ModelParams model_params_of(const SurfaceParameters& surface, const SimulatorOptions& options) {
  ModelParams out;
  out.surface = surface;
  out.effects = options.extra_effects;
  for (const auto& name : out.effects) {
    const auto given = options.effect_parameters.find(name);
    out.effect_parameters[name] = resolve_parameters(
        EffectRegistry::instance().get(name),
        given == options.effect_parameters.end() ? EffectParameterValues{} : given->second);
  }
  return out;
}

ModelParams read_model_params(const std::filesystem::path& path, const SurfaceParameters& defaults) {
  std::ifstream in(path);
  if (!in) throw ParamsError(path.string() + ": cannot open the params file");
  nlohmann::json doc;
  try {
    doc = nlohmann::json::parse(in);
  } catch (const nlohmann::json::parse_error& e) {
    throw ParamsError(path.string() + ": not valid JSON: " + e.what());
  }
  return parse_model_params(doc, defaults, path.string());
}

nlohmann::json model_params_json(const ModelParams& params, const nlohmann::json& extra) {
  nlohmann::json doc = nlohmann::json::object();
  doc["format"] = kFormat;
  for (const auto& f : kSurfaceFields) doc["surface"][f.name] = params.surface.*(f.member);
  doc["effects"] = nlohmann::json::object();
  for (const auto& name : params.effects) {
    const auto values = params.effect_parameters.find(name);
    doc["effects"][name] = values == params.effect_parameters.end() ? nlohmann::json::object()
                                                                     : nlohmann::json(values->second);
  }
  for (const auto& [key, value] : extra.items()) doc[key] = value;
  return doc;
}

void write_model_params(const std::filesystem::path& path, const ModelParams& params, const nlohmann::json& extra) {
  if (path.has_parent_path()) std::filesystem::create_directories(path.parent_path());
  const std::filesystem::path tmp = path.string() + ".tmp";
  {
    std::ofstream out(tmp);
    out << model_params_json(params, extra).dump(2) << "\n";
    if (!out) throw std::runtime_error(tmp.string() + ": cannot write the params file");
  }
  std::filesystem::rename(tmp, path);
}

}  // namespace hj
