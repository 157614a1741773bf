// `hapticjam simulate` and `hapticjam demo`: replay a session's steps and
// write the predicted frame of every capture.
#pragma once

#include <string>
#include <vector>

namespace hj::cli {

int run_simulate(const std::vector<std::string>& args);
int run_demo(const std::vector<std::string>& args);

}  // namespace hj::cli
