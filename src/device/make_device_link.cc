#include "device/make_device_link.h"

#include "device/asio_device_link.h"

namespace hj::device {

std::unique_ptr<DeviceLink> make_device_link(const std::string& endpoint, LinkOptions options) {
  return std::make_unique<AsioDeviceLink>(parse_endpoint(endpoint), options);
}

}  // namespace hj::device
