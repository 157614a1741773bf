// hapticjam-server: flags, the device link, a signal wait. Everything else
// is in hj_server (server.h).
#include <signal.h>
#include <unistd.h>

#include <cstdio>
#include <thread>

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
