// The server's way to a device: a link built from the `--device` endpoint
// string, without naming the transport. The result is not started.
#pragma once

#include <memory>
#include <string>

#include "device/device_link.h"
#include "device/link_options.h"

namespace hj::device {

// An AsioDeviceLink to "HOST:PORT" (TCP) or a serial device path.
// @throws std::invalid_argument naming a bad endpoint or option.
std::unique_ptr<DeviceLink> make_device_link(const std::string& endpoint, LinkOptions options = {});

}  // namespace hj::device
