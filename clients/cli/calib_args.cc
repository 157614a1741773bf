#include "calib_args.h"

#include <fstream>
#include <stdexcept>

#include "args.h"
#include "calib/fit_parameters.h"

namespace hj::cli {

std::vector<std::string> split_list(const std::string& flag, const std::string& text) {
  std::vector<std::string> out;
  size_t start = 0;
  while (true) {
    const size_t comma = text.find(',', start);
    const std::string item = text.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    if (item.empty()) throw std::invalid_argument(flag + " \"" + text + "\": empty item in the list");
    out.push_back(item);
    if (comma == std::string::npos) return out;
    start = comma + 1;
  }
}

CalibArgs parse_calib_args(const std::vector<std::string>& args, const std::set<std::string>& allowed,
                           const std::function<bool(ArgCursor&)>& extra, bool known_effects_only) {
  CalibArgs out;
  std::set<std::string> seen;
  for (ArgCursor cursor(args); cursor.next();) {
    if (extra && extra(cursor)) continue;
    const std::string& a = cursor.arg();
    if (!a.empty() && a[0] == '-') {
      if (!allowed.count(a) && a != "--out") throw std::invalid_argument("unknown option " + a);
      if (!seen.insert(a).second) throw std::invalid_argument(a + " given twice");
    }
    if (a == "--out") out.out = cursor.value();
    else if (a == "--params") out.params_file = cursor.value();
    else if (a == "--effects") out.effects = split_list(a, cursor.value());
    else if (a == "--holdout") out.holdout = split_list(a, cursor.value());
    else if (a == "--profile") out.profile = split_list(a, cursor.value());
    else if (a == "--segments") out.segments = parse_int(a, cursor.value(), 2, 64);
    else if (a == "--threads") out.threads = parse_int(a, cursor.value(), 0, 256);
    else if (a == "--max-iterations") out.max_iterations = parse_int(a, cursor.value(), 1, 1000);
    else if (a == "--no-initial") out.initial_estimates = false;
    else if (a == "--no-screening") out.screening = false;
    else if (a == "--scale-mm") {
      out.scale_mm = parse_number(a, cursor.value());
      if (out.scale_mm <= 0.0) throw std::invalid_argument("--scale-mm must be positive");
    } else if (out.dataset.empty()) out.dataset = a;
    else throw std::invalid_argument("unexpected argument \"" + a + "\"");
  }
  if (out.dataset.empty()) throw std::invalid_argument("missing DATASET (a folder of session folders)");
  if (out.out.empty()) throw std::invalid_argument("missing --out DIR");
  if (known_effects_only)
    for (const auto& e : out.effects) EffectRegistry::instance().get(e);  // names the known effects if unknown
  return out;
}

ModelParams start_params(const CalibArgs& args, const Dataset& dataset) {
  const SurfaceParameters defaults = SurfaceParameters::paper_defaults(dataset.device().geometry(args.segments));
  ModelParams params;
  params.surface = defaults;
  if (!args.params_file.empty()) params = read_model_params(args.params_file, defaults);
  params.surface.max_pressure_pa = dataset.device().max_pressure_kpa * 1000.0;
  return with_effects(params, args.effects);
}

ReplayOptions replay_options(const CalibArgs& args) {
  ReplayOptions out;
  out.segments = args.segments;
  out.threads = args.threads;
  return out;
}

void write_json(const std::filesystem::path& path, const nlohmann::json& doc) {
  if (path.has_parent_path()) std::filesystem::create_directories(path.parent_path());
  std::ofstream out(path);
  out << doc.dump(2) << "\n";
  if (!out) throw std::runtime_error(path.string() + ": cannot write");
}

}  // namespace hj::cli
