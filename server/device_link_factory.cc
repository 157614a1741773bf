#include "device_link_factory.h"

#include "device/make_device_link.h"

namespace hj::server {

std::unique_ptr<device::DeviceLink> open_device_link(const std::string& endpoint) {
  return device::make_device_link(endpoint);
}

}  // namespace hj::server
