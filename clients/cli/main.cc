// hapticjam: the command-line tool.
#include <exception>
#include <iostream>
#include <string>
#include <vector>

#include "plan_command.h"
#include "simulate_command.h"

namespace {

constexpr const char* kUsage =
    "usage: hapticjam COMMAND [ARGS]\n"
    "commands:\n"
    "  simulate SESSION.json --out DIR   replay a session's steps, write predicted frames\n"
    "  demo [--out DIR]                  simulate the paper's Fig. 7 sequence (embedded)\n"
    "  plan GOAL --rows R --cols C --out DIR   plan a goal shape (Algorithm 2)\n"
    "run 'hapticjam COMMAND --help' for a command's options\n";

}  // namespace

int main(int argc, char** argv) {
  const std::vector<std::string> args(argv + std::min(argc, 2), argv + argc);
  const std::string command = argc > 1 ? argv[1] : "";
  try {
    if (command == "simulate") return hj::cli::run_simulate(args);
    if (command == "demo") return hj::cli::run_demo(args);
    if (command == "plan") return hj::cli::run_plan(args);
    if (command == "--help" || command == "-h" || command == "help") {
      std::cout << kUsage;
      return 0;
    }
    std::cerr << (command.empty() ? "hapticjam: missing command\n" : "hapticjam: unknown command \"" + command + "\"\n")
              << kUsage;
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "hapticjam " << command << ": error: " << e.what() << "\n";
    return 1;
  }
}
