// The link's own record of the device state: what an acknowledged command
// changed, so status() answers without a round trip.
#pragma once

#include "device/device_link.h"

namespace hj::device {

// `action` was acknowledged: record its effect. Indices outside the
// recorded array (a device that reported another size) are ignored.
void mirror_action(DeviceStatus& status, const Action& action);
// `vent` was acknowledged: pressure 0, nothing jammed or pinned.
void mirror_vent(DeviceStatus& status);

}  // namespace hj::device
