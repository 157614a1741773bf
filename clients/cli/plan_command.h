// `hapticjam plan`: a goal file in, an Algorithm 2 (or other) plan out,
// with its predicted surface, correlation and Laplace mean.
#pragma once

#include <string>
#include <vector>

namespace hj::cli {

int run_plan(const std::vector<std::string>& args);

}  // namespace hj::cli
