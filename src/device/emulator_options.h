// The command line of hapticjam-device-emulator: every flag, its default,
// and one validation that names the flag that is wrong.
#pragma once

#include <string>
#include <vector>

#include "device/emulator.h"
#include "device/emulator_server.h"

namespace hj::device {

extern const char* const kEmulatorUsage;

struct EmulatorProgramOptions {
  EmulatorConfig config;
  EmulatorServerOptions server;
  bool help = false;
};

// Parses the arguments after the program name, reading --params. Throws
// std::invalid_argument naming the flag (or params file and key) that is
// wrong.
EmulatorProgramOptions parse_emulator_options(const std::vector<std::string>& args);

}  // namespace hj::device
