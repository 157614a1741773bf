// hapticjam synth: a synthetic dataset from a dataset's sessions and a model.
#pragma once

#include <string>
#include <vector>

namespace hj::cli {

int run_synth(const std::vector<std::string>& args);

}  // namespace hj::cli
