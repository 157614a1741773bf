// Shared pieces of the command-line subcommands: checked number parsing and
// the --help / usage-error / run sequence every subcommand follows.
#pragma once

#include <functional>
#include <iostream>
#include <stdexcept>
#include <string>
#include <vector>

namespace hj::cli {

// A finite number; std::invalid_argument naming the flag otherwise.
double parse_number(const std::string& flag, const std::string& text);
// A whole number in [lo, hi]; std::invalid_argument naming the flag otherwise.
int parse_int(const std::string& flag, const std::string& text, int lo, int hi);

// Prints usage for --help (exit 0); runs parse_and_run, turning its
// std::invalid_argument from parsing into a usage error (exit 2). parse
// must throw only on bad arguments; run's own errors propagate.
template <class Args>
int run_subcommand(const std::string& name, const char* usage, const std::vector<std::string>& args,
                   const std::function<Args(const std::vector<std::string>&)>& parse,
                   const std::function<int(const Args&)>& run) {
  for (const auto& a : args)
    if (a == "--help" || a == "-h") {
      std::cout << usage;
      return 0;
    }
  Args parsed;
  try {
    parsed = parse(args);
  } catch (const std::invalid_argument& e) {
    std::cerr << "hapticjam " << name << ": " << e.what() << "\n" << usage;
    return 2;
  }
  return run(parsed);
}

}  // namespace hj::cli
