// The real SocketCAN transport. It needs a kernel with AF_CAN and a CAN interface; where either
// is missing the test says which and skips. With a virtual bus,
//   sudo modprobe vcan && sudo ip link add dev vcan0 type vcan && sudo ip link set up vcan0
// it runs the ATI sensor against its emulator on a second socket on the same bus.
#include <gtest/gtest.h>

#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <string>

#include "pliant/drivers/socketcan/raw_can_transport.hpp"
#include "socketcan_fixture.hpp"

namespace pliant::drivers::socketcan {
namespace {

using hal::HalStatus;

RawCanConfig on(const char* name) {
  RawCanConfig c;
  std::memset(c.interface_name, 0, sizeof c.interface_name);
  std::strncpy(c.interface_name, name, sizeof c.interface_name - 1);
  return c;
}

TEST(SocketCanRaw, InvalidInterfaceNamesAreRefused) {
  RawCanTransport empty(on(""));
  EXPECT_EQ(empty.open(), HalStatus::invalid_argument);
  RawCanConfig c = on("x");
  std::memset(c.interface_name, 'x', sizeof c.interface_name);  // no terminator
  RawCanTransport unterminated(c);
  EXPECT_EQ(unterminated.open(), HalStatus::invalid_argument);
  EXPECT_FALSE(unterminated.is_open());
  CanFrame f;
  CanRxInfo info;
  EXPECT_EQ(unterminated.receive(f, info), CanIo::disconnected);
  EXPECT_EQ(unterminated.send(f), CanIo::disconnected);
}

TEST(SocketCanRaw, AtiSensorOverVcan0) {
  RawCanTransport device_end(on("vcan0"));
  const HalStatus opened = device_end.open();
  if (opened == HalStatus::unsupported) {
    GTEST_SKIP() << "this kernel has no AF_CAN: socket(PF_CAN, SOCK_RAW, CAN_RAW) failed with "
                 << std::strerror(device_end.last_errno()) << " (errno " << device_end.last_errno()
                 << "); the socketpair transport covers the driver here";
  }
  if (opened == HalStatus::disconnected) {
    GTEST_SKIP() << "AF_CAN is available but there is no vcan0 interface (" << std::strerror(device_end.last_errno())
                 << "); create one with: modprobe vcan && ip link add dev vcan0 type vcan && ip link set up vcan0";
  }
  ASSERT_EQ(opened, HalStatus::ok) << std::strerror(device_end.last_errno());
  device_end.close();  // configure opens it with the sensor's filter

  RawCanTransport sensor_end(on("vcan0"));
  ASSERT_EQ(sensor_end.open(), HalStatus::ok);
  hal::ManualClock clock{10.0};
  AtiEmulatorConfig ec;
  ec.calibration = test::hand_calibration();
  AtiNetCanEmulator emulator(sensor_end, ec);
  emulator.set_gauges(test::kHandGauges);
  AtiNetCanConfig config;
  config.calibration_index = 3;
  AtiNetCanForceTorque ft(device_end, clock, config);
  ASSERT_EQ(ft.configure(), HalStatus::ok);
  ASSERT_EQ(ft.start(), HalStatus::ok);
  // vcan delivers synchronously to the other sockets on the bus, so stepping is deterministic.
  hal::WrenchReading w;
  HalStatus s = HalStatus::no_data;
  for (int i = 0; i < 100 && s != HalStatus::ok; ++i) {
    (void)clock.advance(test::kTick);
    s = ft.read(w);
    emulator.service();
  }
  ASSERT_EQ(s, HalStatus::ok);
  test::expect_hand(w);
  EXPECT_LE(w.header.stamp_s, clock.now_s());
  EXPECT_EQ(ft.protocol_counters().dropped_frames(), 0u);
  // Frames for other base IDs never reach the device: the kernel filter drops them.
  const std::uint8_t payload[8] = {};
  ASSERT_EQ(sensor_end.send(make_standard_frame(0x555, payload, 8)), CanIo::ok);
  (void)clock.advance(test::kTick);
  (void)ft.read(w);
  EXPECT_EQ(ft.protocol_counters().foreign_frames, 0u);
  ASSERT_EQ(ft.stop(), HalStatus::ok);
  ASSERT_EQ(ft.cleanup(), HalStatus::ok);
  EXPECT_FALSE(device_end.is_open());
}

}  // namespace
}  // namespace pliant::drivers::socketcan
