// drivers/usb in a hal::DeviceRegistry (usb_registration.hpp): the discovery "usb" runs libusb's
// enumeration and gives the rows and table of list_usb_devices() (which may be empty: containers
// have no USB; a note then says why).
#include <gtest/gtest.h>

#include <string>

#include "pliant/drivers/usb/usb_registration.hpp"

namespace pliant::drivers {
namespace {

TEST(UsbRegistration, RegistersTheUsbDiscovery) {
  hal::DeviceRegistry registry;
  register_usb_devices(registry);
  const hal::DiscoveryInfo* info = registry.find_discovery("usb");
  ASSERT_NE(info, nullptr);
  EXPECT_EQ(info->driver, "usb");
  EXPECT_TRUE(registry.schemes().empty());  // it opens no device itself
  EXPECT_EQ(registry.drivers(), std::vector<std::string>{"usb"});

  hal::DiscoveryOptions options;
  options.include_unknown = true;
  const hal::Discovery found = registry.discover("usb", options);
  EXPECT_FALSE(found.text.empty());  // a table, or "no known USB devices found" and the notes
  if (found.devices.empty()) {
    EXPECT_NE(found.text.find("no known USB devices found"), std::string::npos) << found.text;
  }
  for (const hal::DiscoveredDevice& d : found.devices) {
    EXPECT_FALSE(d.id.empty());
    EXPECT_FALSE(d.handled_by.empty());
    EXPECT_NE(found.text.find(d.id), std::string::npos) << d.id;
  }
}

}  // namespace
}  // namespace pliant::drivers
