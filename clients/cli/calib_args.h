// Options shared by the measurement commands (compare, fit, diagnose), the
// model they start from, and their JSON output.
#pragma once

#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <vector>

#include "args.h"
#include "calib/dataset.h"
#include "calib/model_params.h"
#include "calib/residuals.h"

namespace hj::cli {

struct CalibArgs {
  std::string dataset;
  std::string out;
  std::string params_file;            // --params
  std::vector<std::string> effects;   // --effects a,b
  std::vector<std::string> holdout;   // --holdout NAME,NAME
  std::vector<std::string> profile;   // --profile NAME,NAME (qualified parameter names)
  int segments = 4;
  int threads = 0;                    // 0: one per core
  int max_iterations = 20;
  bool initial_estimates = true;      // --no-initial turns off levelling + Algorithm 1
  bool screening = true;              // --no-screening: diagnose refits every candidate
  double scale_mm = 5.0;              // heat map colour scale
};

// Parses DATASET and the options in `allowed` (e.g. "--params");
// std::invalid_argument naming an unknown, repeated or malformed option.
// `extra`, if given, is offered each argument first and returns true for
// one it took (e.g. the remote commands' --server). With
// known_effects_only, an effect this build does not have is an error (a
// server may have more: the remote commands leave that to it).
CalibArgs parse_calib_args(const std::vector<std::string>& args, const std::set<std::string>& allowed,
                           const std::function<bool(ArgCursor&)>& extra = {}, bool known_effects_only = true);

// "a,b" -> {"a", "b"}; std::invalid_argument naming the flag on an empty item.
std::vector<std::string> split_list(const std::string& flag, const std::string& text);

// The model to start from: --params (missing surface fields from the paper's
// defaults for this device) or the defaults, with --effects switched on.
ModelParams start_params(const CalibArgs& args, const Dataset& dataset);

ReplayOptions replay_options(const CalibArgs& args);

// Writes a JSON document (2-space indent); std::runtime_error naming the
// file if it cannot.
void write_json(const std::filesystem::path& path, const nlohmann::json& doc);

}  // namespace hj::cli
