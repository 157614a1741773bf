#include "device/serial_line.h"

#include <termios.h>

namespace hj::device {

boost::system::error_code open_serial_line(boost::asio::serial_port& port, const std::string& device,
                                           unsigned baud_rate) {
  using boost::asio::serial_port;
  boost::system::error_code ec;
  port.open(device, ec);
  if (!ec) port.set_option(serial_port::baud_rate(baud_rate), ec);
  if (!ec) port.set_option(serial_port::character_size(8), ec);
  if (!ec) port.set_option(serial_port::parity(serial_port::parity::none), ec);
  if (!ec) port.set_option(serial_port::stop_bits(serial_port::stop_bits::one), ec);
  if (!ec) port.set_option(serial_port::flow_control(serial_port::flow_control::none), ec);
  if (!ec) ::tcflush(port.native_handle(), TCIOFLUSH);
  return ec;
}

}  // namespace hj::device
