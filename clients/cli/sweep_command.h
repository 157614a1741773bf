// `hapticjam sweep`: many goals at many array sizes, in parallel; the
// paper's Figs. 11 and 13 and Table 2 from the results.
#pragma once

#include <string>
#include <vector>

namespace hj::cli {

int run_sweep_command(const std::vector<std::string>& args);

}  // namespace hj::cli
