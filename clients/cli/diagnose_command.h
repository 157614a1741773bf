// hapticjam diagnose DATASET --out DIR
#pragma once

#include <string>
#include <vector>

namespace hj::cli {

int run_diagnose(const std::vector<std::string>& args);

}  // namespace hj::cli
