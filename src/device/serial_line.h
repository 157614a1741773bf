// Opens a serial port as the device protocol expects it (PROTOCOL.md):
// the given baud rate, 8 data bits, no parity, one stop bit, no flow
// control, and whatever the device sent before (half a reply) discarded.
#pragma once

#include <boost/asio/serial_port.hpp>
#include <boost/system/error_code.hpp>
#include <string>

namespace hj::device {

// Returns the first error (the port is then not to be used).
boost::system::error_code open_serial_line(boost::asio::serial_port& port, const std::string& device,
                                           unsigned baud_rate);

}  // namespace hj::device
