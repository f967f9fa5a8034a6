// pliant drivers/usb: what Linux's sysfs says about one USB device, readable without opening it
// (no device permissions needed): its manufacturer, product and serial strings, and the network
// interfaces its kernel driver created (a USB-CAN adapter's "can0").
//
// Layout read, under `sysfs_root` (normally "/sys"; tests pass a directory they built):
//   bus/usb/devices/<name>/{manufacturer,product,serial}           one line each
//   bus/usb/devices/<name>:<config>.<interface>/net/<ifname>/      one directory per netdev
// where <name> is usb_sysfs_name(key) ("1-2.3"). Missing files leave fields empty. Each string
// is read up to 255 bytes, cut at the first line break, and bytes outside printable ASCII
// become '?'. Never throws (file system errors leave the result empty).
// Not real-time code. Thread safety: reentrant.
#pragma once

#include <string>
#include <vector>

#include "pliant/drivers/usb/usb_presence.hpp"

namespace pliant::drivers::usb {

struct UsbSysfsInfo {
  bool found = false;  ///< the device directory exists
  std::string manufacturer;
  std::string product;
  std::string serial;
  std::vector<std::string> net_interfaces;  ///< sorted
};

UsbSysfsInfo read_usb_sysfs(const std::string& sysfs_root, const UsbDeviceKey& key);

}  // namespace pliant::drivers::usb
