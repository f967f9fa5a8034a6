// pliant drivers/usb: the USB vendor and product ids of the devices pliant knows how to use (or
// knows it cannot use), and which pliant driver handles each. docs/drivers/usb.md lists the
// sources (libfreenect, OpenNI2's PS1080/PSLink enumeration, Orbbec's udev rules, librealsense,
// the Linux kernel's peak_usb, gs_usb and kvaser_usb drivers).
//
// Kinds: depth cameras; parts of a depth camera that are not the camera (a Kinect's motor and
// audio, the UVC colour side of an Orbbec Astra Pro); USB-CAN adapters. The adapters appear to
// programs as SocketCAN network interfaces (canN) through their kernel drivers, never through
// libusb: pliant's socketcan driver opens the interface, and discovery only maps the physical
// adapter to its interface name (usb_sysfs.hpp).
//
// Matching: entries are tried in table order, specific products first, then product ranges,
// then whole vendors (only for vendors whose every product is a device of that kind: PrimeSense,
// Orbbec, Kvaser). Shared vendor ids (Intel 8086, OpenMoko 1d50, pid.codes 1209, MCS 16d0)
// match only their listed products.
// Real-time safety: lookup is O(table size), allocation-free, noexcept; the table is static.
// Thread safety: pure.
#pragma once

#include <cstddef>
#include <cstdint>

namespace pliant::drivers::usb {

enum class UsbDeviceKind : std::uint8_t {
  depth_camera,  ///< a depth sensor
  camera_part,   ///< a part of a depth camera that does not stream depth (motor, audio, UVC colour)
  can_adapter,   ///< a USB-CAN interface (a SocketCAN netdev through its kernel driver)
};

/// Short stable name ("depth_camera", "camera_part", "can_adapter").
const char* usb_device_kind_name(UsbDeviceKind kind) noexcept;

struct UsbIdEntry {
  std::uint16_t vendor_id;
  std::uint16_t product_first;  ///< inclusive range of product ids
  std::uint16_t product_last;
  UsbDeviceKind kind;
  const char* name;        ///< e.g. "Microsoft Kinect v1 (Xbox 360) camera"
  const char* handled_by;  ///< the pliant driver: "openni2", "socketcan", "opencv", or "none"
  const char* note;        ///< what else is needed, or why nothing handles it ("" if nothing)
};

/// The whole table, in match order (static storage; `count` receives its length).
const UsbIdEntry* usb_id_table(std::size_t& count) noexcept;

/// The first entry matching vendor:product, or nullptr for a device pliant does not know.
const UsbIdEntry* lookup_usb_id(std::uint16_t vendor_id, std::uint16_t product_id) noexcept;

}  // namespace pliant::drivers::usb
