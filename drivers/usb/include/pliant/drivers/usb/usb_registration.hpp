// pliant drivers/usb: its discovery in a hal::DeviceRegistry (hal/device_registry.hpp).
//
// Discovery "usb": the connected USB devices pliant knows (depth cameras, USB-CAN adapters; the
// VID:PID table of usb_ids.hpp), with sysfs details (for an adapter, the canN interface to give
// ati-can: or robotous-can:), or every USB device with DiscoveryOptions::include_unknown. The
// rows and text are those of list_usb_devices() and format_usb_device_table() (usb_devices.hpp).
// Never fails: without USB (containers) the list is empty and a note says why.
// Host code (allocates, throws on a duplicate registration).
#pragma once

#include "pliant/hal/device_registry.hpp"

namespace pliant::drivers {

/// Registers the discovery "usb".
void register_usb_devices(hal::DeviceRegistry& registry);

}  // namespace pliant::drivers
