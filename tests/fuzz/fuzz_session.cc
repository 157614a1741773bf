// libFuzzer: the session reader (src/calib/session.cc): the input is a
// session.json. Anything but SessionError escaping is a finding.
#include <cstddef>
#include <cstdint>
#include <string>

#include "calib/session.h"
#include "fuzz_folder.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto dir = hj::fuzz::folder() / "session";
  std::filesystem::create_directories(dir);
  hj::fuzz::write_file(dir / "session.json", std::string(reinterpret_cast<const char*>(data), size));
  try {
    hj::read_session(dir);
  } catch (const hj::SessionError&) {
  }
  return 0;
}
