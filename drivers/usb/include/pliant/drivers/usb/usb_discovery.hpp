// pliant drivers/usb: finding USB devices with libusb 1.0 (Debian 12: 1.0.26; facts in
// docs/drivers/usb.md): a one-shot enumeration, and a watch that reports arrivals and
// departures through a non-blocking poll().
//
// Watching: with hotplug support (libusb_has_capability(LIBUSB_CAP_HAS_HOTPLUG)), one callback
// is registered for every device with LIBUSB_HOTPLUG_ENUMERATE, so the devices present at
// watch() arrive too; libusb runs the callback inside libusb_handle_events_timeout_completed(),
// which poll() calls with a zero timeout, so callbacks run in the polling thread and need no
// lock. The callback does no I/O: it reads the device's descriptor (which libusb documents as
// safe on a departing device) and its bus, port path and address (fields libusb keeps in the
// device structure, with the parent devices referenced), and feeds UsbPresence, which drops
// libusb's duplicate reports. Without hotplug, poll() enumerates again and reconciles.
//
// Never fails: when libusb cannot start (libusb_init fails, e.g. without usbfs) or sees no bus,
// every call returns empty results and note() says why. Containers typically have no
// /dev/bus/usb: libusb 1.0.26 then starts, supports hotplug and lists nothing.
//
// Not real-time code: enumerate() and poll() allocate (libusb's device list, the event vector).
// Thread safety: one thread per instance; separate instances have separate libusb contexts.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "pliant/drivers/usb/usb_presence.hpp"

namespace pliant::drivers::usb {

class UsbDiscovery {
 public:
  UsbDiscovery();
  /// Deregisters the watch and closes libusb.
  ~UsbDiscovery();
  UsbDiscovery(const UsbDiscovery&) = delete;
  UsbDiscovery& operator=(const UsbDiscovery&) = delete;

  /// Starts libusb (once; later calls return the first outcome). False, with a note, when it
  /// cannot: the other calls then return nothing.
  bool open();
  bool usable() const noexcept;
  /// Why results may be empty or incomplete ("" when nothing to say).
  const std::string& note() const noexcept { return note_; }

  /// Every device on the buses now (opens libusb if needed). Devices whose descriptor cannot
  /// be read are skipped and counted in skipped().
  std::vector<UsbDeviceInfo> enumerate();
  std::uint64_t skipped() const noexcept { return skipped_; }

  /// Starts reporting changes (opens libusb if needed). The devices present now are reported
  /// as arrivals by the next poll(). False (and a note) when libusb is unusable.
  bool watch();
  /// True when watching through libusb hotplug, false when poll() re-enumerates.
  bool hotplug() const noexcept { return hotplug_; }
  /// Non-blocking: appends the arrivals and departures since the last poll, each device once.
  void poll(std::vector<UsbEvent>& events);
  /// The devices present as of the last poll().
  const UsbPresence& presence() const noexcept { return presence_; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::string note_;
  std::uint64_t skipped_ = 0;
  bool opened_ = false;
  bool watching_ = false;
  bool hotplug_ = false;
  UsbPresence presence_;
  std::vector<UsbEvent> pending_;  // filled by the hotplug callback between polls
  friend struct UsbDiscoveryCallback;
};

}  // namespace pliant::drivers::usb
