// hapticjam: the command-line tool.
#include <algorithm>
#include <exception>
#include <functional>
#include <iostream>
#include <string>
#include <vector>

#include "compare_command.h"
#include "diagnose_command.h"
#include "fit_command.h"
#include "plan_command.h"
#include "remote_command.h"
#include "simulate_command.h"
#include "synth_command.h"
#include "sweep_command.h"

namespace {

struct Command {
  const char* name;
  std::function<int(const std::vector<std::string>&)> run;
};

// One line per subcommand; each lives in its own *_command.cc.
const std::vector<Command> kCommands = {
    {"simulate", hj::cli::run_simulate},
    {"demo", hj::cli::run_demo},
    {"plan", hj::cli::run_plan},
    {"synth", hj::cli::run_synth},
    {"remote", hj::cli::run_remote},
    {"sweep", hj::cli::run_sweep_command},
    {"compare", hj::cli::run_compare},
    {"fit", hj::cli::run_fit},
    {"diagnose", hj::cli::run_diagnose},
};

constexpr const char* kUsage =
    "usage: hapticjam COMMAND [ARGS]\n"
    "commands:\n"
    "  simulate SESSION.json --out DIR   replay a session's steps, write predicted frames\n"
    "  demo [--out DIR]                  simulate the paper's Fig. 7 sequence (embedded)\n"
    "  plan GOAL --rows R --cols C --out DIR   plan a goal shape (Algorithm 2)\n"
    "  synth DATASET --out DIR           a synthetic dataset: DATASET's sessions replayed with a model + noise\n"
    "  remote SUBCOMMAND --server HOST:PORT    a client of hapticjam-server (plan, preview,\n"
    "                                    submit, watch, cancel, status, stop, resume ...)\n"
    "  sweep GOAL... --out DIR           every goal at every array size, Figs. 11/13, Table 2\n"
    "  compare DATASET --out DIR         model versus measured frames: errors, heat maps, report\n"
    "  fit DATASET --out DIR             fit the model's parameters to a dataset (params.json)\n"
    "  diagnose DATASET --out DIR        find the effect(s) the model is missing\n"
    "run 'hapticjam COMMAND --help' for a command's options\n";

}  // namespace

int main(int argc, char** argv) {
  const std::vector<std::string> args(argv + std::min(argc, 2), argv + argc);
  const std::string command = argc > 1 ? argv[1] : "";
  try {
    for (const auto& c : kCommands)
      if (command == c.name) return c.run(args);
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
