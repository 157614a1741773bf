#include "device/link_options.h"

#include <charconv>
#include <stdexcept>

namespace hj::device {

void LinkOptions::validate() const {
  const auto positive = [](std::chrono::milliseconds v, const char* name) {
    if (v.count() <= 0) throw std::invalid_argument(std::string("LinkOptions.") + name + " must be > 0 ms");
  };
  positive(connect_timeout, "connect_timeout");
  positive(heartbeat_interval, "heartbeat_interval");
  positive(heartbeat_timeout, "heartbeat_timeout");
  positive(backoff_initial, "backoff_initial");
  positive(backoff_max, "backoff_max");
  if (heartbeat_timeout <= heartbeat_interval)
    throw std::invalid_argument("LinkOptions.heartbeat_timeout (ms) must exceed heartbeat_interval");
  if (backoff_max < backoff_initial)
    throw std::invalid_argument("LinkOptions.backoff_max (ms) must be >= backoff_initial");
  if (!(backoff_factor >= 1.0 && backoff_factor <= 100.0))
    throw std::invalid_argument("LinkOptions.backoff_factor must be within [1, 100]");
  if (baud_rate == 0) throw std::invalid_argument("LinkOptions.baud_rate must be > 0");
}

std::string Endpoint::to_string() const {
  if (kind == Kind::kSerial) return device;
  const bool v6 = host.find(':') != std::string::npos;
  return (v6 ? "[" + host + "]" : host) + ":" + std::to_string(port);
}

Endpoint parse_endpoint(const std::string& text) {
  const auto bad = [&](const std::string& why) {
    return std::invalid_argument("device endpoint \"" + text + "\": " + why +
                                 " (expected HOST:PORT or a serial device path like /dev/ttyUSB0)");
  };
  Endpoint e;
  if (!text.empty() && text.front() == '/') {
    e.kind = Endpoint::Kind::kSerial;
    e.device = text;
    return e;
  }
  const std::size_t colon = text.rfind(':');
  if (colon == std::string::npos) throw bad("no port");
  std::string host = text.substr(0, colon);
  if (host.size() >= 2 && host.front() == '[' && host.back() == ']') host = host.substr(1, host.size() - 2);
  else if (host.find(':') != std::string::npos) throw bad("an IPv6 address needs brackets");
  if (host.empty()) throw bad("empty host");
  const std::string port_text = text.substr(colon + 1);
  unsigned long port = 0;
  const auto [end, ec] = std::from_chars(port_text.data(), port_text.data() + port_text.size(), port);
  if (port_text.empty() || ec != std::errc() || end != port_text.data() + port_text.size() || port < 1 ||
      port > 65535)
    throw bad("port \"" + port_text + "\" is not a whole number in 1..65535");
  e.host = host;
  e.port = static_cast<unsigned short>(port);
  return e;
}

}  // namespace hj::device
