// drivers/modbus in a hal::DeviceRegistry (modbus_registration.hpp): the four schemes, an FT 300
// and a Robotiq gripper opened by spec against the emulator over Modbus TCP (tare on start, the
// gripper never activated, the driver's counters in info()), malformed parameters, and the
// reason of a refused connection. The links keep the factories' 20 ms answer budget, so reads
// are retried on a timeout (a loaded machine may miss it once).
#include <gtest/gtest.h>

#include <string>
#include <variant>

#include "pliant/drivers/modbus/emulator/modbus_emulator.hpp"
#include "pliant/drivers/modbus/modbus_registration.hpp"

namespace pliant::drivers::modbus {
namespace {

using hal::HalStatus;

hal::DeviceSpec tcp_spec(const std::string& scheme, std::uint16_t port) {
  hal::DeviceSpec spec;
  spec.scheme = scheme;
  spec.location = "127.0.0.1";
  spec.parameters["port"] = std::to_string(port);
  return spec;
}

// The field `name` of `info`, or nullptr.
const hal::DeviceInfo::Value* field(const hal::DeviceInfo& info, const std::string& name) {
  for (const hal::DeviceInfo::Field& f : info.fields()) {
    if (f.name == name) return &f.value;
  }
  return nullptr;
}

// Reads until a sample arrives (the clock moves past the poll period between tries).
template <class Device, class Sample>
HalStatus read_sample(Device& device, Sample& out, hal::ManualClock& clock) {
  HalStatus status = HalStatus::no_data;
  for (int attempt = 0; attempt < 50 && status != HalStatus::ok; ++attempt) {
    EXPECT_EQ(clock.advance(0.2), HalStatus::ok);  // past the poll period and any reconnect wait
    status = device.read(out);
  }
  return status;
}

TEST(ModbusRegistration, RegistersItsSchemes) {
  hal::DeviceRegistry registry;
  register_modbus_devices(registry);
  for (const char* scheme : {"ft300-rtu", "ft300-tcp"}) {
    const hal::SchemeInfo* info = registry.find(hal::DeviceCategory::force_torque, scheme);
    ASSERT_NE(info, nullptr) << scheme;
    EXPECT_EQ(info->driver, "modbus");
  }
  for (const char* scheme : {"robotiq-rtu", "robotiq-tcp"}) {
    ASSERT_NE(registry.find(hal::DeviceCategory::gripper, scheme), nullptr) << scheme;
  }
  EXPECT_EQ(registry.schemes().size(), 4u);
  EXPECT_THROW(register_modbus_devices(registry), std::invalid_argument);  // twice
}

TEST(ModbusRegistration, OpensAnFt300AndAGripperBySpec) {
  ModbusEmulator emulator;
  ASSERT_TRUE(emulator.start());
  hal::DeviceRegistry registry;
  register_modbus_devices(registry);
  hal::ManualClock clock;

  hal::DeviceSpec ft_spec = tcp_spec("ft300-tcp", emulator.port());
  ft_spec.parameters["tare"] = "true";
  hal::OpenResult ft = registry.open(hal::DeviceCategory::force_torque, ft_spec, clock);
  ASSERT_TRUE(ft) << ft.error;
  EXPECT_EQ(ft.driver, "modbus");
  ASSERT_NE(ft.device->force_torque(), nullptr);
  const double w[6] = {1.0, 2.0, -3.0, 0.1, 0.2, 0.3};
  emulator.set_wrench(w);
  ASSERT_EQ(ft.device->start(), HalStatus::ok);
  hal::WrenchReading r;
  ASSERT_EQ(read_sample(*ft.device->force_torque(), r, clock), HalStatus::ok);
  for (double v : r.wrench) EXPECT_DOUBLE_EQ(v, 0.0);  // tared on the first sample
  const hal::DeviceInfo ft_info = ft.device->info();
  ASSERT_NE(field(ft_info, "mode"), nullptr);
  EXPECT_EQ(std::get<std::string>(*field(ft_info, "mode")), "polling");
  EXPECT_EQ(std::get<std::uint64_t>(*field(ft_info, "tares")), 1u);
  ASSERT_NE(field(ft_info, "link.transactions"), nullptr);
  EXPECT_GE(std::get<std::uint64_t>(*field(ft_info, "link.transactions")), 1u);

  hal::DeviceSpec grip_spec = tcp_spec("robotiq-tcp", emulator.port());
  grip_spec.parameters["stroke_m"] = "0.14";
  hal::OpenResult gripper = registry.open(hal::DeviceCategory::gripper, grip_spec, clock);
  ASSERT_TRUE(gripper) << gripper.error;
  ASSERT_NE(gripper.device->gripper(), nullptr);
  ASSERT_EQ(gripper.device->start(), HalStatus::ok);
  hal::GripperReading g;
  ASSERT_EQ(read_sample(*gripper.device->gripper(), g, clock), HalStatus::ok);
  emulator.advance(1.0);
  ASSERT_EQ(read_sample(*gripper.device->gripper(), g, clock), HalStatus::ok);
  EXPECT_EQ(emulator.counters().command_writes, 0u);  // opened by spec: never activated
  const hal::DeviceInfo grip_info = gripper.device->info();
  EXPECT_DOUBLE_EQ(std::get<double>(*field(grip_info, "stroke_m")), 0.14);
  EXPECT_FALSE(std::get<bool>(*field(grip_info, "activated")));
  EXPECT_NE(field(grip_info, "link.timeouts"), nullptr);
}

TEST(ModbusRegistration, MalformedParametersAndARefusedConnection) {
  hal::DeviceRegistry registry;
  register_modbus_devices(registry);
  hal::ManualClock clock;
  hal::DeviceSpec spec = tcp_spec("robotiq-tcp", 502);
  spec.parameters["slave"] = "300";
  hal::OpenResult bad = registry.open(hal::DeviceCategory::gripper, spec, clock);
  EXPECT_EQ(bad.status, HalStatus::invalid_argument);
  EXPECT_EQ(bad.error, "parameter 'slave' = '300': expected an integer 0..247");
  spec.parameters["slave"] = "9";
  spec.parameters["stroke_m"] = "2";
  EXPECT_EQ(registry.open(hal::DeviceCategory::gripper, spec, clock).status, HalStatus::invalid_argument);
  spec.parameters.erase("stroke_m");
  spec.parameters["tare"] = "true";  // a sensor's parameter, not the gripper's
  EXPECT_EQ(registry.open(hal::DeviceCategory::gripper, spec, clock).error,
            "robotiq-tcp has no parameter 'tare' (it takes port, slave, stroke_m)");

  std::uint16_t closed_port = 0;
  {
    ModbusEmulator emulator;
    ASSERT_TRUE(emulator.start());
    closed_port = emulator.port();
  }
  hal::OpenResult refused = registry.open(hal::DeviceCategory::force_torque, tcp_spec("ft300-tcp", closed_port), clock);
  EXPECT_FALSE(refused);
  EXPECT_NE(refused.status, HalStatus::invalid_argument);
  EXPECT_NE(refused.error.find("refused"), std::string::npos) << refused.error;
}

}  // namespace
}  // namespace pliant::drivers::modbus
