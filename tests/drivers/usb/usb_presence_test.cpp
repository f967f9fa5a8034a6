// drivers/usb usb_presence: the idempotent bookkeeping of arrivals and departures, fed with the
// event patterns libusb's hotplug with ENUMERATE can produce (duplicate arrivals, departures of
// devices never reported), replacements and polling reconciliation.
#include <gtest/gtest.h>

#include <vector>

#include "pliant/drivers/usb/usb_presence.hpp"

namespace {

using namespace pliant::drivers::usb;

UsbDeviceInfo device(std::uint8_t bus, std::uint8_t address, std::vector<std::uint8_t> ports, std::uint16_t vid,
                     std::uint16_t pid) {
  UsbDeviceInfo d;
  d.key.bus = bus;
  d.key.address = address;
  d.key.port_count = static_cast<std::uint8_t>(ports.size());
  for (std::size_t i = 0; i < ports.size(); ++i) d.key.ports[i] = ports[i];
  d.vendor_id = vid;
  d.product_id = pid;
  return d;
}

TEST(UsbPresence, KeysAndSysfsNames) {
  const UsbDeviceInfo a = device(1, 4, {2, 3}, 0x045e, 0x02ae);
  EXPECT_EQ(usb_sysfs_name(a.key), "1-2.3");
  EXPECT_EQ(usb_sysfs_name(device(3, 1, {}, 0x1d6b, 0x0002).key), "usb3");
  EXPECT_EQ(usb_sysfs_name(device(2, 9, {1, 4, 2, 7}, 0, 0).key), "2-1.4.2.7");
  UsbDeviceKey other = a.key;
  EXPECT_EQ(other, a.key);
  other.address = 5;
  EXPECT_NE(other, a.key);
  other = a.key;
  other.ports[1] = 4;
  EXPECT_NE(other, a.key);
  other = a.key;
  other.ports[5] = 9;  // beyond port_count: not part of the key
  EXPECT_EQ(other, a.key);
}

TEST(UsbPresence, ReportsEachArrivalAndDepartureOnce) {
  UsbPresence presence;
  std::vector<UsbEvent> events;
  const UsbDeviceInfo kinect = device(1, 4, {2}, 0x045e, 0x02ae);
  const UsbDeviceInfo pcan = device(1, 5, {3}, 0x0c72, 0x000c);
  // ENUMERATE reports the kinect, then the real arrival event reports it again.
  presence.arrive(kinect, events);
  presence.arrive(pcan, events);
  presence.arrive(kinect, events);
  ASSERT_EQ(events.size(), 2u);
  EXPECT_EQ(events[0].kind, UsbEventKind::arrived);
  EXPECT_EQ(events[0].device.key, kinect.key);
  EXPECT_EQ(events[1].device.vendor_id, 0x0c72);
  EXPECT_EQ(presence.present().size(), 2u);
  EXPECT_EQ(presence.counters().duplicates, 1u);

  // A departure of a device never reported, then the kinect leaves twice.
  events.clear();
  presence.leave(device(1, 9, {4}, 0x1234, 0x5678).key, events);
  presence.leave(kinect.key, events);
  presence.leave(kinect.key, events);
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(events[0].kind, UsbEventKind::left);
  EXPECT_EQ(events[0].device.product_id, 0x02ae) << "departures carry the ids it arrived with";
  EXPECT_EQ(presence.present().size(), 1u);
  EXPECT_EQ(presence.counters().arrivals, 2u);
  EXPECT_EQ(presence.counters().departures, 1u);
  EXPECT_EQ(presence.counters().duplicates, 3u);

  // Re-plugged: a new address, so a new key and a new arrival.
  events.clear();
  presence.arrive(device(1, 6, {2}, 0x045e, 0x02ae), events);
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(events[0].device.key.address, 6);
}

TEST(UsbPresence, AnotherDeviceAtAPresentKeyReplacesIt) {
  UsbPresence presence;
  std::vector<UsbEvent> events;
  presence.arrive(device(1, 4, {2}, 0x045e, 0x02ae), events);
  events.clear();
  presence.arrive(device(1, 4, {2}, 0x1d27, 0x0601), events);
  ASSERT_EQ(events.size(), 2u);
  EXPECT_EQ(events[0].kind, UsbEventKind::left);
  EXPECT_EQ(events[0].device.vendor_id, 0x045e);
  EXPECT_EQ(events[1].kind, UsbEventKind::arrived);
  EXPECT_EQ(events[1].device.vendor_id, 0x1d27);
  ASSERT_EQ(presence.present().size(), 1u);
  EXPECT_EQ(presence.present()[0].vendor_id, 0x1d27);
}

TEST(UsbPresence, ReconcileReportsTheDifferences) {
  UsbPresence presence;
  std::vector<UsbEvent> events;
  const UsbDeviceInfo a = device(1, 2, {1}, 0x0c72, 0x000c);
  const UsbDeviceInfo b = device(1, 3, {2}, 0x1d50, 0x606f);
  const UsbDeviceInfo c = device(2, 2, {1, 1}, 0x2bc5, 0x0401);
  presence.reconcile({a, b}, events);
  ASSERT_EQ(events.size(), 2u);
  events.clear();
  presence.reconcile({a, b}, events);
  EXPECT_TRUE(events.empty()) << "nothing changed";
  presence.reconcile({b, c, c}, events);  // a left, c arrived (listed twice)
  ASSERT_EQ(events.size(), 2u);
  EXPECT_EQ(events[0].kind, UsbEventKind::left);
  EXPECT_EQ(events[0].device.key, a.key);
  EXPECT_EQ(events[1].kind, UsbEventKind::arrived);
  EXPECT_EQ(events[1].device.key, c.key);
  events.clear();
  UsbDeviceInfo b_replaced = b;
  b_replaced.product_id = 0x6070;
  presence.reconcile({b_replaced, c}, events);
  ASSERT_EQ(events.size(), 2u);
  EXPECT_EQ(events[0].kind, UsbEventKind::left);
  EXPECT_EQ(events[1].kind, UsbEventKind::arrived);
  EXPECT_EQ(events[1].device.product_id, 0x6070);
  events.clear();
  presence.reconcile({}, events);
  EXPECT_EQ(events.size(), 2u);
  EXPECT_TRUE(presence.present().empty());
}

// Any interleaving of duplicate events ends with the same set as the clean sequence, and the
// reported events always alternate arrived/left per key.
TEST(UsbPresence, RandomDuplicatedStreamsStayConsistent) {
  std::vector<UsbDeviceInfo> pool;
  for (std::uint8_t i = 1; i <= 5; ++i) pool.push_back(device(1, i, {i}, 0x0c72, 0x000c));
  unsigned state = 12345;
  const auto next = [&state]() { return state = state * 1103515245u + 12345u, (state >> 16) & 0x7fffu; };
  UsbPresence presence;
  std::vector<bool> truth(pool.size(), false);
  std::vector<bool> reported(pool.size(), false);
  for (int step = 0; step < 2000; ++step) {
    const std::size_t i = next() % pool.size();
    const bool arrive = (next() % 2) == 0;
    std::vector<UsbEvent> events;
    if (arrive) {
      presence.arrive(pool[i], events);
    } else {
      presence.leave(pool[i].key, events);
    }
    truth[i] = arrive;
    for (const UsbEvent& e : events) {
      const std::size_t j = e.device.key.address - 1u;
      ASSERT_NE(reported[j], e.kind == UsbEventKind::arrived) << "an event repeated the state";
      reported[j] = e.kind == UsbEventKind::arrived;
    }
    ASSERT_EQ(reported, truth);
  }
}

}  // namespace
