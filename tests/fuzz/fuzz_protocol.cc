// libFuzzer: every parser of the device line protocol (src/device/protocol.h)
// on arbitrary bytes. The first byte picks the parser; anything but a
// ProtocolError escaping is a finding, and a request that parses must
// survive formatting and parsing again unchanged.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "device/protocol.h"

namespace protocol = hj::device::protocol;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  const std::string_view text(reinterpret_cast<const char*>(data) + 1, size - 1);
  try {
    switch (data[0] % 5) {
      case 0: {
        const protocol::Request request = protocol::parse_request(text);
        const std::string again = protocol::format_request(request);
        if (protocol::format_request(protocol::parse_request(again)) != again) __builtin_trap();
        break;
      }
      case 1: protocol::parse_reply(text); break;
      case 2: protocol::parse_hello(text); break;
      case 3: protocol::parse_status(text, 1 + data[0] / 5 % 8, 1 + data[0] / 40 % 8); break;
      default: protocol::parse_capture(text); break;
    }
  } catch (const protocol::ProtocolError&) {
  }
  return 0;
}
