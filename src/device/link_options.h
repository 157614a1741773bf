// How the device link connects, beats and reconnects, and where to: the
// endpoint string of `--device` ("HOST:PORT", "[::1]:PORT" or a serial
// device path such as "/dev/ttyUSB0").
#pragma once

#include <chrono>
#include <string>

namespace hj::device {

struct LinkOptions {
  // Opening the connection plus the "hello" exchange.
  std::chrono::milliseconds connect_timeout{2000};
  // A "ping" this often while connected; nothing at all received for
  // heartbeat_timeout means the link is down (a silent drop is found
  // within heartbeat_timeout + heartbeat_interval; a closed one at once).
  std::chrono::milliseconds heartbeat_interval{200};
  std::chrono::milliseconds heartbeat_timeout{800};
  // Reconnect delays: initial, times backoff_factor after each failed
  // attempt, at most backoff_max; back to initial after a success.
  std::chrono::milliseconds backoff_initial{100};
  std::chrono::milliseconds backoff_max{5000};
  double backoff_factor = 2.0;
  // Serial ports only: 8N1 at this rate.
  unsigned baud_rate = 115200;

  // Throws std::invalid_argument naming the field (and its unit) that is
  // not positive, or a heartbeat_timeout not above heartbeat_interval.
  void validate() const;
};

struct Endpoint {
  enum class Kind { kTcp, kSerial };
  Kind kind = Kind::kTcp;
  std::string host;          // kTcp, without brackets
  unsigned short port = 0;   // kTcp
  std::string device;        // kSerial

  std::string to_string() const;
};

// "HOST:PORT" / "[V6]:PORT" / "/dev/..." (any absolute path is a serial
// device). Throws std::invalid_argument naming the endpoint and what is
// wrong (no port, a port outside 1..65535, an empty host).
Endpoint parse_endpoint(const std::string& text);

}  // namespace hj::device
