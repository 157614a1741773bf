#include "remote_command.h"

#include <functional>
#include <iostream>

namespace hj::cli {

namespace {

struct Subcommand {
  const char* name;
  std::function<int(const std::vector<std::string>&)> run;
};

const std::vector<Subcommand> kSubcommands = {
    {"plan", run_remote_plan},     {"preview", run_remote_preview}, {"planners", run_remote_planners},
    {"submit", run_remote_submit}, {"watch", run_remote_watch},     {"job", run_remote_job},
    {"cancel", run_remote_cancel}, {"status", run_remote_status},   {"stop", run_remote_stop},
    {"resume", run_remote_resume}, {"bench", run_remote_bench},     {"render", run_remote_render},
    {"compare", run_remote_compare}, {"fit", run_remote_fit},       {"diagnose", run_remote_diagnose},
};

constexpr const char* kRemoteUsage =
    "usage: hapticjam remote SUBCOMMAND --server HOST:PORT [--token T] [ARGS]\n"
    "A client of hapticjam-server (proto/hapticjam/v1). Subcommands:\n"
    "  plan GOAL|--map NAME --rows R --cols C --out DIR   plan on the server, live progress\n"
    "  preview GOAL|--map NAME --rows R --cols C          quick predicted surface and scores\n"
    "  planners                     planners, server maps and goal formats\n"
    "  submit PLAN.json [--wait]    queue a plan on the shared device\n"
    "  watch [--job ID]             follow the device queue\n"
    "  job ID [--out DIR]           one job, its captured frames\n"
    "  cancel ID                    cancel a queued or running job\n"
    "  status                       the device: connection, state, last capture\n"
    "  stop [--reason TEXT]         emergency stop: vent the device now, pause the queue\n"
    "  resume                       let a paused queue run again\n"
    "  render GOAL --rows R --cols C  render on the device with the loop closed (capture, correct)\n"
    "  bench                        Preview calls per second and latency\n"
    "  compare|fit|diagnose DATASET --out DIR   the measurement workbench on the server\n"
    "Exit codes: 0 done, 2 usage, 10 + the gRPC status code when the server refuses\n"
    "(13 INVALID_ARGUMENT, 17 PERMISSION_DENIED, 18 RESOURCE_EXHAUSTED, 19 FAILED_PRECONDITION,\n"
    "24 UNAVAILABLE, 26 UNAUTHENTICATED ...). 'hapticjam remote SUBCOMMAND --help' for options.\n";

}  // namespace

int run_remote(const std::vector<std::string>& args) {
  const std::string sub = args.empty() ? "" : args.front();
  for (const auto& s : kSubcommands)
    if (sub == s.name) return s.run(std::vector<std::string>(args.begin() + 1, args.end()));
  if (sub == "--help" || sub == "-h" || sub == "help") {
    std::cout << kRemoteUsage;
    return 0;
  }
  std::cerr << (sub.empty() ? "hapticjam remote: missing subcommand\n" : "hapticjam remote: unknown subcommand \"" + sub + "\"\n")
            << kRemoteUsage;
  return 2;
}

}  // namespace hj::cli
