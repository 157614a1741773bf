// hapticjam-device-emulator: the device protocol on TCP in front of the
// simulator (see emulator_options.cc for the flags).
#include <pthread.h>
#include <signal.h>

#include <cstdio>
#include <iostream>

#include "device/emulator_options.h"

int main(int argc, char** argv) {
  using namespace hj::device;
  EmulatorProgramOptions options;
  try {
    options = parse_emulator_options({argv + 1, argv + argc});
  } catch (const std::invalid_argument& e) {
    std::cerr << "hapticjam-device-emulator: " << e.what() << "\n" << kEmulatorUsage;
    return 2;
  }
  if (options.help) {
    std::cout << kEmulatorUsage;
    return 0;
  }
  // Signals are taken by sigwait below, not by the server's threads.
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);
  options.server.on_vent = [](const std::string& why) {
    std::fprintf(stderr, "hapticjam-device-emulator: vented (%s)\n", why.c_str());
  };
  try {
    Emulator emulator(options.config);
    EmulatorServer server(emulator, options.server);
    server.start();
    const auto& g = options.config.geometry;
    std::printf("hapticjam-device-emulator: listening on %s:%u (%d x %d cells of %g mm, max %g kPa)\n",
                options.server.host.c_str(), static_cast<unsigned>(server.port()), g.rows, g.cols,
                g.cell_size_m * 1000.0, options.config.params.max_pressure_pa / 1000.0);
    std::fflush(stdout);
    int signal = 0;
    sigwait(&signals, &signal);
    server.stop();
    std::printf("hapticjam-device-emulator: stopped (%ld commands answered)\n", server.commands_answered());
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "hapticjam-device-emulator: " << e.what() << "\n";
    return 1;
  }
}
