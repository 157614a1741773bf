// `hapticjam remote SUBCOMMAND`: the command line as a client of a
// hapticjam-server, over the public gRPC API only (proto/hapticjam/v1).
// One family of subcommands per file: remote_planning.cc (plan, preview,
// planners), remote_device.cc (submit, watch, job, cancel, status, stop,
// resume), remote_bench.cc (bench), remote_render.cc (render).
#pragma once

#include <string>
#include <vector>

namespace hj::cli {

int run_remote(const std::vector<std::string>& args);

int run_remote_plan(const std::vector<std::string>& args);
int run_remote_preview(const std::vector<std::string>& args);
int run_remote_planners(const std::vector<std::string>& args);

int run_remote_submit(const std::vector<std::string>& args);
int run_remote_watch(const std::vector<std::string>& args);
int run_remote_job(const std::vector<std::string>& args);
int run_remote_cancel(const std::vector<std::string>& args);
int run_remote_status(const std::vector<std::string>& args);
int run_remote_stop(const std::vector<std::string>& args);
int run_remote_resume(const std::vector<std::string>& args);

int run_remote_bench(const std::vector<std::string>& args);
int run_remote_render(const std::vector<std::string>& args);

int run_remote_compare(const std::vector<std::string>& args);
int run_remote_fit(const std::vector<std::string>& args);
int run_remote_diagnose(const std::vector<std::string>& args);

}  // namespace hj::cli
