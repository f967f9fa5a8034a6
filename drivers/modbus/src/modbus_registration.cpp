#include "pliant/drivers/modbus/modbus_registration.hpp"

#include <cstring>
#include <memory>
#include <string>
#include <utility>

#include "pliant/drivers/modbus/robotiq_ft300.hpp"
#include "pliant/drivers/modbus/robotiq_gripper.hpp"

namespace pliant::drivers {
namespace {

namespace mb = modbus;

std::string errno_text(int err) {
  if (err <= 0) return std::string();
  if (err < 4096) return std::strerror(err);
  return "Modbus error " + std::to_string(err);  // libmodbus's own codes (EMB*)
}

void set_link(const hal::DeviceSpec& spec, bool tcp, mb::ModbusLinkConfig& link) {
  link.transport = tcp ? mb::ModbusTransport::tcp : mb::ModbusTransport::rtu;
  if (tcp) {
    link.host = spec.location;
    link.port = static_cast<int>(spec.integer("port", 1, 65535, 502));
  } else {
    link.device = spec.location;
  }
  link.slave_id = static_cast<int>(spec.integer("slave", 0, 247, 9));
}

hal::DeviceInfo link_info(const mb::ModbusLinkCounters& l) {
  hal::DeviceInfo info;
  info.add("transactions", l.transactions)
      .add("failures", l.failures)
      .add("timeouts", l.timeouts)
      .add("bad_responses", l.bad_responses)
      .add("disconnects", l.disconnects)
      .add("reconnects", l.reconnects);
  return info;
}

class OpenedGripper final : public hal::OpenedDevice {
 public:
  OpenedGripper(const hal::Clock& clock, const mb::RobotiqGripperConfig& config) : gripper_(clock, config) {}
  ~OpenedGripper() override { shut_down(gripper_); }
  hal::Device& device() noexcept override { return gripper_; }
  hal::Gripper* gripper() noexcept override { return &gripper_; }
  std::string last_error() const override { return errno_text(gripper_.link_counters().last_errno); }
  hal::DeviceInfo info() const override {
    hal::DeviceInfo info;
    info.add("stroke_m", gripper_.config().scaling.stroke_m)
        .add("activated", gripper_.activated())
        .add("fc03", gripper_.using_holding_registers())
        .add("polls_skipped", gripper_.driver_counters().polls_skipped)
        .nest("link", link_info(gripper_.link_counters()));
    return info;
  }

 private:
  mb::RobotiqGripper gripper_;
};

class OpenedFt300 final : public hal::OpenedDevice {
 public:
  OpenedFt300(const hal::Clock& clock, const mb::RobotiqFt300Config& config, bool tare)
      : sensor_(clock, config), tare_(tare) {}
  ~OpenedFt300() override { shut_down(sensor_); }
  hal::Device& device() noexcept override { return sensor_; }
  hal::ForceTorqueSensor* force_torque() noexcept override { return &sensor_; }
  std::string last_error() const override { return errno_text(sensor_.link_counters().last_errno); }
  hal::DeviceInfo info() const override {
    const bool stream = sensor_.config().mode == mb::Ft300Mode::stream;
    hal::DeviceInfo info;
    info.add("mode", stream ? "stream" : "polling").add("tares", sensor_.driver_counters().tares);
    if (stream) {
      info.add("stream_timeouts", sensor_.driver_counters().stream_timeouts)
          .add("reconnects", sensor_.driver_counters().reconnects);
    } else {
      info.nest("link", link_info(sensor_.link_counters()));
    }
    return info;
  }

 protected:
  void on_started() noexcept override {
    if (tare_) sensor_.request_tare();
  }

 private:
  mb::RobotiqFt300 sensor_;
  bool tare_;
};

template <class Opened>
hal::OpenResult configured(std::unique_ptr<Opened> opened) {
  const hal::HalStatus status = opened->device().configure();
  if (status != hal::HalStatus::ok) return hal::OpenResult::failure(status, opened->last_error());
  return hal::OpenResult::success(std::move(opened));
}

hal::OpenResult open_gripper(const hal::DeviceSpec& spec, const hal::Clock& clock, bool tcp) {
  mb::RobotiqGripperConfig c;
  set_link(spec, tcp, c.link);
  c.scaling.stroke_m = spec.number("stroke_m", 0.001, 1.0, 0.085);
  c.activation = mb::ActivationPolicy::never;  // opened by spec text: never moves the fingers on its own
  c.min_poll_period_s = 0.01;
  return configured(std::make_unique<OpenedGripper>(clock, c));
}

hal::OpenResult open_ft300(const hal::DeviceSpec& spec, const hal::Clock& clock, bool tcp) {
  mb::RobotiqFt300Config c;
  set_link(spec, tcp, c.link);
  c.mode = tcp ? mb::Ft300Mode::polling : mb::Ft300Mode::stream;
  c.min_poll_period_s = 0.005;
  return configured(std::make_unique<OpenedFt300>(clock, c, spec.flag("tare", false)));
}

}  // namespace

void register_modbus_devices(hal::DeviceRegistry& registry) {
  registry.add({hal::DeviceCategory::force_torque,
                "ft300-rtu",
                "modbus",
                "a serial device (/dev/ttyUSB1)",
                "Robotiq FT 300 in stream mode",
                {"slave", "tare"}},
               [](const hal::DeviceSpec& spec, const hal::Clock& clock) { return open_ft300(spec, clock, false); });
  registry.add({hal::DeviceCategory::force_torque,
                "ft300-tcp",
                "modbus",
                "an IPv4 address (192.168.1.11)",
                "Robotiq FT 300 polled through a Modbus TCP gateway",
                {"port", "slave", "tare"}},
               [](const hal::DeviceSpec& spec, const hal::Clock& clock) { return open_ft300(spec, clock, true); });
  registry.add({hal::DeviceCategory::gripper,
                "robotiq-rtu",
                "modbus",
                "a serial device (/dev/ttyUSB0)",
                "Robotiq 2F-85/140 gripper over Modbus RTU (never activated on open)",
                {"slave", "stroke_m"}},
               [](const hal::DeviceSpec& spec, const hal::Clock& clock) { return open_gripper(spec, clock, false); });
  registry.add({hal::DeviceCategory::gripper,
                "robotiq-tcp",
                "modbus",
                "an IPv4 address (192.168.1.11)",
                "Robotiq 2F-85/140 gripper through Modbus TCP (never activated on open)",
                {"port", "slave", "stroke_m"}},
               [](const hal::DeviceSpec& spec, const hal::Clock& clock) { return open_gripper(spec, clock, true); });
}

}  // namespace pliant::drivers
