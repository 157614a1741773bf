// libFuzzer: the device link's line splitter (src/device/line_buffer.h) fed
// arbitrary bytes in arbitrary chunks: no line it hands out is longer than
// its limit or holds a newline.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "device/line_buffer.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 2) return 0;
  const std::size_t limit = 1 + data[0] % 64, chunk = 1 + data[1] % 17;
  hj::device::LineBuffer lines(limit);
  const std::string_view bytes(reinterpret_cast<const char*>(data) + 2, size - 2);
  for (std::size_t at = 0; at < bytes.size(); at += chunk)
    lines.feed(
        bytes.substr(at, chunk),
        [&](std::string_view line) {
          if (line.size() > limit || line.find('\n') != std::string_view::npos) __builtin_trap();
        },
        [] {});
  return 0;
}
