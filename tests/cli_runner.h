// Runs the hapticjam CLI (HJ_CLI_PATH) from tests: quoting, exit code, and
// the output captured in files.
#pragma once

#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace hj::testing_support {

inline std::string quoted(const std::filesystem::path& p) {
  std::string out(1, '\'');
  out += p.string();
  out += '\'';
  return out;
}

// Runs the CLI with `args`, stdout and stderr to dir/stdout.txt and
// dir/stderr.txt; returns the exit code (-1 if it did not exit normally).
inline int run_cli(const std::string& args, const std::filesystem::path& dir) {
  const std::string command = quoted(HJ_CLI_PATH) + " " + args + " >" + quoted(dir / "stdout.txt") + " 2>" +
                              quoted(dir / "stderr.txt");
  const int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

inline std::string read_text(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace hj::testing_support
