// drivers/usb usb_discovery: real libusb calls on this machine. They must work (return a list,
// possibly empty, with a note) whether or not it has USB devices; the events a watch reports are
// checked against a fresh enumeration.
#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "pliant/drivers/usb/usb_discovery.hpp"

namespace {

using namespace pliant::drivers::usb;

TEST(UsbDiscovery, EnumerateWorksWithWhateverIsConnected) {
  UsbDiscovery discovery;
  const std::vector<UsbDeviceInfo> devices = discovery.enumerate();
  if (!discovery.usable()) {
    EXPECT_TRUE(devices.empty());
    EXPECT_FALSE(discovery.note().empty());
    return;
  }
  if (devices.empty()) {
    EXPECT_NE(discovery.note().find("no USB device"), std::string::npos) << discovery.note();
  }
  for (const UsbDeviceInfo& d : devices) {
    EXPECT_GE(d.key.bus, 1) << "bus numbers start at 1";
    EXPECT_LE(d.key.port_count, 7);
  }
  // A second enumeration of an idle machine sees the same devices.
  EXPECT_EQ(discovery.enumerate().size(), devices.size());
}

TEST(UsbDiscovery, WatchReportsThePresentDevicesOnce) {
  UsbDiscovery discovery;
  if (!discovery.watch()) {
    EXPECT_FALSE(discovery.note().empty());
    std::vector<UsbEvent> events;
    discovery.poll(events);
    EXPECT_TRUE(events.empty());
    return;
  }
  EXPECT_TRUE(discovery.watch()) << "idempotent";
  std::vector<UsbEvent> events;
  discovery.poll(events);
  discovery.poll(events);
  discovery.poll(events);
  const std::vector<UsbDeviceInfo> now = discovery.enumerate();
  // Every present device arrived exactly once (nothing is plugged during the test).
  EXPECT_EQ(discovery.presence().present().size(), now.size());
  std::size_t arrivals = 0;
  for (const UsbEvent& e : events) {
    EXPECT_EQ(e.kind, UsbEventKind::arrived);
    ++arrivals;
    EXPECT_TRUE(std::any_of(now.begin(), now.end(), [&](const UsbDeviceInfo& d) { return d.key == e.device.key; }));
  }
  EXPECT_EQ(arrivals, now.size());
}

TEST(UsbDiscovery, CallsBeforeOpeningAreHarmless) {
  UsbDiscovery discovery;
  std::vector<UsbEvent> events;
  discovery.poll(events);  // not watching: nothing
  EXPECT_TRUE(events.empty());
  EXPECT_FALSE(discovery.hotplug());
  EXPECT_TRUE(discovery.presence().present().empty());
}

}  // namespace
