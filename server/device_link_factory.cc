#include "device_link_factory.h"

#include <stdexcept>

namespace hj::server {

std::unique_ptr<device::DeviceLink> open_device_link(const std::string& endpoint) {
  // The Asio link (src/device, branch `device`) is not merged yet.
  throw std::invalid_argument("--device " + endpoint +
                              ": the device link is not built into this server yet (src/device has only the contract)");
}

}  // namespace hj::server
