// hapticjam-server: flags, the device link, a signal wait. Everything else
// is in hj_server (server.h).
#include <pthread.h>
#include <signal.h>

#include <cstdio>
#include <iostream>
#include <thread>

#include "device_link_factory.h"
#include "json_log.h"
#include "server.h"

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

  // SIGINT and SIGTERM go to one thread that shuts the server down; block
  // them before any other thread exists so none of those receives them.
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);

  try {
    std::unique_ptr<hj::device::DeviceLink> link;
    if (!options.device.empty()) link = open_device_link(options.device);
    HapticServer server(options, std::move(link));
    std::printf("hapticjam-server listening on port %d\n", server.port());
    std::fflush(stdout);
    std::thread waiter([&] {
      int received = 0;
      sigwait(&signals, &received);
      log_event("signal", {{"signal", received == SIGINT ? "SIGINT" : "SIGTERM"}});
      server.shutdown();
    });
    server.wait();
    // The waiter returns once a signal came; if the server stopped otherwise, send it one.
    pthread_kill(waiter.native_handle(), SIGTERM);
    waiter.join();
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "hapticjam-server: %s\n", e.what());
    return 1;
  }
}
