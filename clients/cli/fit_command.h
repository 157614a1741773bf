// hapticjam fit DATASET [--effects a,b] [--holdout NAMES] [--params START] --out DIR
#pragma once

#include <string>
#include <vector>

namespace hj::cli {

int run_fit(const std::vector<std::string>& args);

}  // namespace hj::cli
