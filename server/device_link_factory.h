// Opens the link to the array's controller named by --device.
#pragma once

#include <memory>
#include <string>

#include "device/device_link.h"

namespace hj::server {

// @throws std::invalid_argument naming the endpoint if no link can be made.
std::unique_ptr<device::DeviceLink> open_device_link(const std::string& endpoint);

}  // namespace hj::server
