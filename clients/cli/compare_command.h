// hapticjam compare DATASET [--params FILE] [--effects a,b] --out DIR
#pragma once

#include <string>
#include <vector>

namespace hj::cli {

int run_compare(const std::vector<std::string>& args);

}  // namespace hj::cli
