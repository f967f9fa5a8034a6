// pliant drivers/usb: the device list of `pliant devices`, as printable rows.
//
//   std::vector<std::string> notes;
//   const auto rows = pliant::drivers::usb::list_usb_devices({}, notes);
//   std::cout << pliant::drivers::usb::format_usb_device_table(rows, notes);
//
// Each row is one connected device pliant knows (usb_ids.hpp), or any device with
// include_unknown: its name, kind, VID:PID, bus/address and port path, the pliant driver that
// handles it, and what sysfs adds (product and serial strings; for a USB-CAN adapter the canN
// interface its kernel driver created, which is what pliant's socketcan driver opens).
// Never fails: without USB (containers) the list is empty and `notes` says why.
// Not real-time code. Thread safety: reentrant (each call has its own libusb context).
#pragma once

#include <string>
#include <vector>

#include "pliant/drivers/usb/usb_presence.hpp"

namespace pliant::drivers::usb {

struct UsbRowOptions {
  bool include_unknown = false;     ///< also list devices the table does not know
  std::string sysfs_root = "/sys";  ///< where to read strings and interface names ("" = skip)
};

struct UsbDeviceRow {
  std::string name;        ///< from the table ("unknown device" otherwise)
  std::string kind;        ///< usb_device_kind_name, or "other"
  std::string id;          ///< "045e:02ae"
  std::string location;    ///< "001/004 1-2.3": bus/address and sysfs port path
  std::string handled_by;  ///< "openni2", "socketcan", "opencv" or "none"
  std::string detail;      ///< the table's note, sysfs product/serial, "interface can0"
  UsbDeviceInfo device;
};

/// Rows for `devices` (table lookup plus sysfs), in the order given.
std::vector<UsbDeviceRow> describe_usb_devices(const std::vector<UsbDeviceInfo>& devices, const UsbRowOptions& options);

/// Enumerates with libusb (UsbDiscovery) and describes; `notes` gets libusb's note, if any.
std::vector<UsbDeviceRow> list_usb_devices(const UsbRowOptions& options, std::vector<std::string>& notes);

/// A text table: a header and one aligned line per row, then the notes; "no known USB devices
/// found" instead of the table when `rows` is empty.
std::string format_usb_device_table(const std::vector<UsbDeviceRow>& rows, const std::vector<std::string>& notes);

}  // namespace pliant::drivers::usb
