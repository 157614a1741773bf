// hapticjam-server: flags, the device link, the web viewer's gateway as a
// child process (--http), a signal wait. Everything else is in hj_server
// (server.h).
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "device/make_device_link.h"
#include "job_store.h"
#include "json_log.h"
#include "server.h"

namespace {

// Exit codes: 1 any other failure, 2 bad flags, 3 the job database cannot
// be opened (corrupt, not a database, held by another server).
constexpr int kExitStoreError = 3;

// SIGINT / SIGTERM write their number into this pipe; a thread reads it and
// shuts the server down (a handler may run on any thread, libraries start
// some before main, so the handler does nothing but write).
int g_signal_pipe[2] = {-1, -1};

void on_signal(int number) {
  const char byte = char(number);
  [[maybe_unused]] const auto written = ::write(g_signal_pipe[1], &byte, 1);
}

// The interpreter and module path of clients/web, set by CMake (clients/CMakeLists.txt).
#ifndef HJ_WEB_PYTHON3
#define HJ_WEB_PYTHON3 ""
#endif
#ifndef HJ_WEB_PYTHONPATH
#define HJ_WEB_PYTHONPATH ""
#endif

// Starts `python3 -m hapticjam_web` serving options.http, pointed at this
// server's own port on loopback and given its maps; it prints its address on
// our stdout and dies with us (PR_SET_PDEATHSIG). Returns its pid.
pid_t start_web_viewer(const hj::server::ServerOptions& options, int grpc_port) {
  if (std::strlen(HJ_WEB_PYTHON3) == 0)
    throw std::runtime_error("--http: built without a python3 that has grpc and protobuf (python3-grpcio)");
  std::vector<std::string> args = {HJ_WEB_PYTHON3, "-m", "hapticjam_web", "--server",
                                   "127.0.0.1:" + std::to_string(grpc_port), "--listen", options.http};
  if (!hj::server::is_loopback_listen(options.http)) args.push_back("--allow-remote");
  for (const auto& [name, file] : options.maps) args.insert(args.end(), {"--map", name + "=" + file});
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  // Our environment with clients/web and the stubs put first on PYTHONPATH.
  const char* before = std::getenv("PYTHONPATH");
  std::vector<std::string> env = {"PYTHONPATH=" + std::string(HJ_WEB_PYTHONPATH) +
                                  (before && *before ? std::string(":") + before : "")};
  for (char** e = environ; *e; ++e)
    if (std::strncmp(*e, "PYTHONPATH=", 11) != 0) env.emplace_back(*e);
  std::vector<char*> envp;
  for (auto& e : env) envp.push_back(e.data());
  envp.push_back(nullptr);
  const pid_t parent = ::getpid();
  const pid_t pid = ::fork();
  if (pid < 0) throw std::runtime_error(std::string("--http: fork: ") + std::strerror(errno));
  if (pid == 0) {  // the child: only async-signal-safe calls until exec
    ::prctl(PR_SET_PDEATHSIG, SIGTERM);
    if (::getppid() != parent) ::_exit(1);
    ::execve(argv[0], argv.data(), envp.data());
    ::_exit(127);
  }
  hj::server::log_event("web_viewer", {{"pid", int(pid)}, {"http", options.http}});
  return pid;
}

void stop_web_viewer(pid_t pid) {
  if (pid <= 0) return;
  ::kill(pid, SIGTERM);
  int status = 0;
  ::waitpid(pid, &status, 0);
}

}  // namespace

int main(int argc, char** argv) {
  using namespace hj::server;
  ServerOptions options;
  try {
    bool help = false;
    options = parse_server_args(std::vector<std::string>(argv + 1, argv + argc), &help);
    if (help) {
      std::fputs(kServerUsage, stdout);
      return 0;
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "hapticjam-server: %s (see --help)\n", e.what());
    return 2;
  }

  if (::pipe(g_signal_pipe) != 0) {
    std::perror("hapticjam-server: pipe");
    return 1;
  }
  struct sigaction action {};
  action.sa_handler = on_signal;
  sigemptyset(&action.sa_mask);
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);

  try {
    std::unique_ptr<hj::device::DeviceLink> link;
    if (!options.device.empty()) link = hj::device::make_device_link(options.device);
    HapticServer server(options, std::move(link));
    std::printf("hapticjam-server listening on port %d\n", server.port());
    std::fflush(stdout);
    const pid_t web_viewer = options.http.empty() ? 0 : start_web_viewer(options, server.port());
    std::thread waiter([&] {
      char number = 0;
      while (::read(g_signal_pipe[0], &number, 1) < 0) {
      }
      if (number != 0) log_event("signal", {{"signal", number == SIGINT ? "SIGINT" : "SIGTERM"}});
      server.shutdown();
    });
    server.wait();
    on_signal(0);  // wakes the waiter if the server stopped by itself
    waiter.join();
    stop_web_viewer(web_viewer);
    return 0;
  } catch (const StoreError& e) {
    // Not worth a restart loop: the file needs a person (kExitStoreError).
    std::fprintf(stderr, "hapticjam-server: %s (exit %d: the job database cannot be used; fix or move it)\n",
                 e.what(), kExitStoreError);
    return kExitStoreError;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "hapticjam-server: %s\n", e.what());
    return 1;
  }
}
