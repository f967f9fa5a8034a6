// drivers/socketcan in a hal::DeviceRegistry (socketcan_registration.hpp): the two schemes, their
// parameters, and the reason given when the CAN interface is missing (or the kernel has no
// AF_CAN, as in many containers). The sensors themselves are covered over socketpairs by the
// other tests of this folder; the registry always opens a raw AF_CAN socket.
#include <gtest/gtest.h>

#include <string>

#include "pliant/drivers/socketcan/socketcan_registration.hpp"

namespace pliant::drivers::socketcan {
namespace {

using hal::HalStatus;

hal::DeviceSpec spec_of(const std::string& scheme, const std::string& interface_name) {
  hal::DeviceSpec spec;
  spec.scheme = scheme;
  spec.location = interface_name;
  return spec;
}

TEST(SocketCanRegistration, RegistersItsSchemes) {
  hal::DeviceRegistry registry;
  register_socketcan_devices(registry);
  for (const char* scheme : {"ati-can", "robotous-can"}) {
    const hal::SchemeInfo* info = registry.find(hal::DeviceCategory::force_torque, scheme);
    ASSERT_NE(info, nullptr) << scheme;
    EXPECT_EQ(info->driver, "socketcan");
  }
  EXPECT_EQ(registry.schemes().size(), 2u);
}

TEST(SocketCanRegistration, ParametersAreChecked) {
  hal::DeviceRegistry registry;
  register_socketcan_devices(registry);
  hal::ManualClock clock;
  hal::DeviceSpec ati = spec_of("ati-can", "can0");
  hal::OpenResult missing = registry.open(hal::DeviceCategory::force_torque, ati, clock);
  EXPECT_EQ(missing.status, HalStatus::invalid_argument);
  EXPECT_EQ(missing.error, "parameter 'base_id' missing: expected an integer 0..127");
  ati.parameters["base_id"] = "0x80";
  EXPECT_EQ(registry.open(hal::DeviceCategory::force_torque, ati, clock).status, HalStatus::invalid_argument);
  ati.parameters["base_id"] = "0x20";
  ati.location = "a-name-longer-than-15";
  hal::OpenResult long_name = registry.open(hal::DeviceCategory::force_torque, ati, clock);
  EXPECT_EQ(long_name.status, HalStatus::invalid_argument);
  EXPECT_NE(long_name.error.find("must be 1..15 characters"), std::string::npos) << long_name.error;
  hal::DeviceSpec rft = spec_of("robotous-can", "can0");
  rft.parameters["command_id"] = "0x64";
  rft.parameters["response_1"] = "0x800";
  EXPECT_EQ(registry.open(hal::DeviceCategory::force_torque, rft, clock).error,
            "parameter 'response_1' = '0x800': expected an integer 0..2047");
}

TEST(SocketCanRegistration, AMissingInterfaceIsExplained) {
  hal::DeviceRegistry registry;
  register_socketcan_devices(registry);
  hal::ManualClock clock;
  hal::DeviceSpec ati = spec_of("ati-can", "pliantnone0");
  ati.parameters["base_id"] = "32";
  ati.parameters["tare"] = "true";
  const hal::OpenResult opened = registry.open(hal::DeviceCategory::force_torque, ati, clock);
  ASSERT_FALSE(opened);
  EXPECT_EQ(opened.driver, "socketcan");
  if (opened.status == HalStatus::unsupported) {
    EXPECT_EQ(opened.error, "this kernel has no SocketCAN (AF_CAN)");
  } else if (opened.status == HalStatus::disconnected) {
    EXPECT_EQ(opened.error,
              "no CAN interface 'pliantnone0' (plug the adapter in and bring it up: ip link set pliantnone0 up "
              "type can bitrate 1000000)");
  } else {  // another refusal of the socket (a sandbox): its errno in words
    EXPECT_TRUE(hal::is_fault(opened.status)) << hal::hal_status_name(opened.status);
    EXPECT_FALSE(opened.error.empty());
  }
}

}  // namespace
}  // namespace pliant::drivers::socketcan
