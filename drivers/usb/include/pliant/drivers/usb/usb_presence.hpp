// pliant drivers/usb: the set of connected USB devices, kept from arrival and departure events so
// that each change is reported exactly once.
//
// libusb's hotplug with LIBUSB_HOTPLUG_ENUMERATE may report the arrival of one device twice, or
// the departure of a device whose arrival it never reported (libusb hotplug.c). UsbPresence
// turns that stream into changes: an arrival of a device already present, or a departure of one
// not present, produces no event (counted as a duplicate). A device is identified by its key:
// bus, port path and address (docs/drivers/usb.md). A re-plugged device gets a new address and
// so a new key; an arrival at a present key with other vendor:product ids replaces the old
// device (a departure, then an arrival).
// Without hotplug, reconcile() compares a fresh enumeration with the set and reports the
// differences the same way.
//
// Not real-time code: the set and the event lists are std::vectors. Pure: no libusb, no I/O.
// Thread safety: one thread per instance.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace pliant::drivers::usb {

/// Where a device sits: its bus, the ports from the root hub down, and its address.
struct UsbDeviceKey {
  std::uint8_t bus = 0;
  std::uint8_t address = 0;
  std::uint8_t port_count = 0;          ///< 0..7 (USB 3 allows 7 tiers below the root)
  std::array<std::uint8_t, 7> ports{};  ///< ports[0 .. port_count - 1]
  bool operator==(const UsbDeviceKey& other) const noexcept;
  bool operator!=(const UsbDeviceKey& other) const noexcept { return !(*this == other); }
};

/// The kernel's name of the device's sysfs directory: "<bus>-<port>.<port>..." (e.g. "1-2.3"),
/// or "usb<bus>" for a root hub (no ports).
std::string usb_sysfs_name(const UsbDeviceKey& key);

struct UsbDeviceInfo {
  UsbDeviceKey key;
  std::uint16_t vendor_id = 0;
  std::uint16_t product_id = 0;
};

enum class UsbEventKind : std::uint8_t { arrived, left };

struct UsbEvent {
  UsbEventKind kind = UsbEventKind::arrived;
  UsbDeviceInfo device;
};

struct UsbPresenceCounters {
  std::uint64_t arrivals = 0;    ///< arrivals reported
  std::uint64_t departures = 0;  ///< departures reported
  std::uint64_t duplicates = 0;  ///< arrivals of present devices and departures of absent ones, ignored
};

class UsbPresence {
 public:
  /// Appends an `arrived` event unless the device is already present (then nothing).
  void arrive(const UsbDeviceInfo& device, std::vector<UsbEvent>& events);
  /// Appends a `left` event (with the ids it arrived with) if a device with `key` is present.
  void leave(const UsbDeviceKey& key, std::vector<UsbEvent>& events);
  /// Brings the set to `now` (a complete enumeration): departures first, then arrivals.
  void reconcile(const std::vector<UsbDeviceInfo>& now, std::vector<UsbEvent>& events);
  /// Forgets every device without reporting anything.
  void clear() noexcept { present_.clear(); }

  const std::vector<UsbDeviceInfo>& present() const noexcept { return present_; }
  const UsbPresenceCounters& counters() const noexcept { return counters_; }

 private:
  std::vector<UsbDeviceInfo> present_;  // in arrival order
  UsbPresenceCounters counters_;
};

}  // namespace pliant::drivers::usb
