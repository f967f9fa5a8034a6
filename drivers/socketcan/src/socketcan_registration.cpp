#include "pliant/drivers/socketcan/socketcan_registration.hpp"

#include <cstring>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>

#include "pliant/drivers/socketcan/ati_netcanoem_sensor.hpp"
#include "pliant/drivers/socketcan/raw_can_transport.hpp"
#include "pliant/drivers/socketcan/robotous_rft_sensor.hpp"

namespace pliant::drivers {
namespace {

namespace can = socketcan;

can::RawCanConfig raw_can_config(const hal::DeviceSpec& spec) {
  can::RawCanConfig c;
  if (spec.location.empty() || spec.location.size() >= sizeof c.interface_name) {
    throw std::invalid_argument("CAN interface name '" + spec.location.substr(0, 40) + "' must be 1.." +
                                std::to_string(sizeof c.interface_name - 1) + " characters");
  }
  std::memset(c.interface_name, 0, sizeof c.interface_name);
  spec.location.copy(c.interface_name, sizeof c.interface_name - 1);
  return c;
}

// Why configure failed, in words.
std::string configure_reason(hal::HalStatus status, const std::string& interface_name, const can::CanTransport& bus) {
  if (status == hal::HalStatus::unsupported) return "this kernel has no SocketCAN (AF_CAN)";
  if (status == hal::HalStatus::disconnected) {
    return "no CAN interface '" + interface_name + "' (plug the adapter in and bring it up: ip link set " +
           interface_name + " up type can bitrate 1000000)";
  }
  const int err = bus.last_errno();
  return err > 0 ? std::string(std::strerror(err)) : std::string();
}

hal::DeviceInfo link_info(const can::CanLinkCounters& l) {
  hal::DeviceInfo info;
  info.add("frames_received", l.frames_received)
      .add("error_frames", l.error_frames)
      .add("bus_off_events", l.bus_off_events)
      .add("rx_overflows", l.rx_overflows)
      .add("disconnects", l.disconnects)
      .add("reconnects", l.reconnects)
      .add("untrusted_stamps", l.untrusted_stamps);
  return info;
}

class OpenedAti final : public hal::OpenedDevice {
 public:
  OpenedAti(const can::RawCanConfig& bus, const hal::Clock& clock, const can::AtiNetCanConfig& config)
      : bus_(bus), sensor_(bus_, clock, config) {}
  ~OpenedAti() override { shut_down(sensor_); }
  hal::Device& device() noexcept override { return sensor_; }
  hal::ForceTorqueSensor* force_torque() noexcept override { return &sensor_; }
  const can::CanTransport& bus() const noexcept { return bus_; }
  hal::DeviceInfo info() const override {
    const can::AtiCounters& p = sensor_.protocol_counters();
    std::string serial;
    for (const char c : sensor_.info().serial) {
      if (c == '\0') break;
      if (c >= 0x20 && c < 0x7f) serial += c;  // the sensor's bytes, printable ASCII only
    }
    hal::DeviceInfo info;
    info.add("serial", serial)
        .add("firmware", std::to_string(sensor_.info().firmware_major) + "." +
                             std::to_string(sensor_.info().firmware_minor) + "." +
                             std::to_string(sensor_.info().firmware_build))
        .add("ready", sensor_.ready())
        .add("polls_sent", p.polls_sent)
        .add("unanswered_polls", p.unanswered_polls)
        .add("incomplete_samples", p.incomplete_samples)
        .add("dropped_frames", p.dropped_frames())
        .add("setup_failures", p.setup_failures)
        .add("tares_completed", p.tares_completed)
        .nest("link", link_info(sensor_.link_counters()));
    return info;
  }

 private:
  can::RawCanTransport bus_;  // declared first: the sensor holds a reference to it
  can::AtiNetCanForceTorque sensor_;
};

class OpenedRobotous final : public hal::OpenedDevice {
 public:
  OpenedRobotous(const can::RawCanConfig& bus, const hal::Clock& clock, const can::RobotousRftConfig& config)
      : bus_(bus), sensor_(bus_, clock, config) {}
  ~OpenedRobotous() override { shut_down(sensor_); }
  hal::Device& device() noexcept override { return sensor_; }
  hal::ForceTorqueSensor* force_torque() noexcept override { return &sensor_; }
  const can::CanTransport& bus() const noexcept { return bus_; }
  hal::DeviceInfo info() const override {
    const can::RftCounters& p = sensor_.protocol_counters();
    hal::DeviceInfo info;
    info.add("stream_requests", p.stream_requests)
        .add("complete_packets", p.complete_packets)
        .add("overload_packets", p.overload_packets)
        .add("incomplete_packets", p.incomplete_packets)
        .add("dropped_frames", p.dropped_frames())
        .nest("link", link_info(sensor_.link_counters()));
    return info;
  }

 private:
  can::RawCanTransport bus_;
  can::RobotousRftForceTorque sensor_;
};

template <class Opened>
hal::OpenResult configured(std::unique_ptr<Opened> opened, const std::string& interface_name) {
  const hal::HalStatus status = opened->device().configure();
  if (status != hal::HalStatus::ok) {
    return hal::OpenResult::failure(status, configure_reason(status, interface_name, opened->bus()));
  }
  return hal::OpenResult::success(std::move(opened));
}

}  // namespace

void register_socketcan_devices(hal::DeviceRegistry& registry) {
  registry.add({hal::DeviceCategory::force_torque,
                "ati-can",
                "socketcan",
                "a CAN interface (can0)",
                "ATI F/T sensor with the NETCANOEM board",
                {"base_id", "tare"}},
               [](const hal::DeviceSpec& spec, const hal::Clock& clock) {
                 can::AtiNetCanConfig c;
                 c.base_id = static_cast<std::uint8_t>(spec.integer("base_id", 0, 0x7f));
                 c.tare_samples_on_start = spec.flag("tare", false) ? 100 : 0;
                 return configured(std::make_unique<OpenedAti>(raw_can_config(spec), clock, c), spec.location);
               });
  registry.add({hal::DeviceCategory::force_torque,
                "robotous-can",
                "socketcan",
                "a CAN interface (can0)",
                "Robotous RFT force/torque sensor",
                {"command_id", "response_1", "response_2", "tare"}},
               [](const hal::DeviceSpec& spec, const hal::Clock& clock) {
                 can::RobotousRftConfig c;
                 c.ids.command = static_cast<std::uint16_t>(spec.integer("command_id", 0, 0x7ff));
                 c.ids.response_1 = static_cast<std::uint16_t>(spec.integer("response_1", 0, 0x7ff, 0x01));
                 c.ids.response_2 = static_cast<std::uint16_t>(spec.integer("response_2", 0, 0x7ff, 0x02));
                 c.bias_on_start = spec.flag("tare", false);
                 return configured(std::make_unique<OpenedRobotous>(raw_can_config(spec), clock, c), spec.location);
               });
}

}  // namespace pliant::drivers
