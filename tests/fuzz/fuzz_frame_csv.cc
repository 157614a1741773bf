// libFuzzer: the depth-camera frame reader (src/calib/frame_csv.cc). The
// first two bytes are the expected rows and columns (1 .. 64 each), the rest
// is the frame's CSV. Anything but SessionError escaping is a finding.
#include <cstddef>
#include <cstdint>
#include <string>

#include "calib/frame_csv.h"
#include "calib/session.h"
#include "fuzz_folder.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 2) return 0;
  const int ny = 1 + data[0] % 64, nx = 1 + data[1] % 64;
  const auto file = hj::fuzz::folder() / "frame.csv";
  hj::fuzz::write_file(file, std::string(reinterpret_cast<const char*>(data) + 2, size - 2));
  try {
    hj::read_frame_csv(file, ny, nx);
  } catch (const hj::SessionError&) {
  }
  return 0;
}
