#include "wire_faults.hpp"

#include "pliant/drivers/socketcan/can_error.hpp"
#include "pliant/hal/force_torque.hpp"
#include "pliant/hal/gripper.hpp"

namespace pliant::hil {
namespace {

namespace can = drivers::socketcan;

constexpr std::uint8_t kOverCurrent = 0x0e;  // gFLT over-current
constexpr long kCameraHoldCycles = 60;

// A camera fault on the mock, from half a period after the current time, for hold cycles.
void schedule_camera(WireRig& rig, hal::FaultKind kind) {
  hal::FaultEvent e;
  e.kind = kind;
  e.start_s = rig.clock.now_s() + 0.5 * rig.period_s();
  e.duration_s = static_cast<double>(kCameraHoldCycles) * rig.period_s();
  (void)rig.observer->add_fault(e);
}

std::uint64_t guard_stale(const WireRig& rig, GuardSource source) {
  return rig.supervisor->guard().counters.stale_cycles[static_cast<int>(source)];
}

}  // namespace

const char* wire_device_name(WireDevice device) noexcept {
  switch (device) {
    case WireDevice::gripper: return "gripper";
    case WireDevice::sensor: return "F/T";
    case WireDevice::camera: return "camera";
    case WireDevice::clock: return "clock";
  }
  return "?";
}

std::vector<WireFault> wire_faults() {
  return {
      {"Modbus timeout", WireDevice::gripper, "drop_replies(1)", [](WireRig& r) { r.gripper_emulator.drop_replies(1); },
       nullptr, [](const WireRig& r) { return r.gripper->link_counters().timeouts; }, nullptr},
      {"Modbus exception", WireDevice::gripper, "fc04 -> exception 1",
       [](WireRig& r) { r.gripper_emulator.set_fc04_supported(false); },
       [](WireRig& r) { r.gripper_emulator.set_fc04_supported(true); },
       [](const WireRig& r) { return r.gripper->link_counters().exceptions; }, nullptr},
      {"Modbus damaged reply", WireDevice::gripper, "corrupt_replies(3)",
       [](WireRig& r) { r.gripper_emulator.corrupt_replies(3); }, nullptr,
       [](const WireRig& r) { return r.gripper->link_counters().bad_responses; }, nullptr},
      {"TCP drop + reconnect", WireDevice::gripper, "disconnect_clients",
       [](WireRig& r) { (void)r.gripper_emulator.disconnect_clients(); }, nullptr,
       [](const WireRig& r) { return r.gripper->link_counters().disconnects; }, nullptr},
      {"gripper fault byte", WireDevice::gripper, "gFLT 0x0E",
       [](WireRig& r) { r.gripper_emulator.set_gripper_fault(kOverCurrent); },
       [](WireRig& r) { r.gripper_emulator.set_gripper_fault(0); },
       [](const WireRig& r) { return r.gripper->counters().fault_samples; }, nullptr},
      // A controller that is bus-off neither sends nor receives: the sensor's answers stop too
      // (a sensor frame arriving would tell the driver the bus works again).
      {"CAN bus-off", WireDevice::sensor, "bus-off frame, bus quiet",
       [](WireRig& r) {
         r.sensor_emulator->faults().mute = true;
         (void)r.sensor_emulator->send_error(can::kCanErrBusOff);
       },
       [](WireRig& r) {
         r.sensor_emulator->faults().mute = false;
         (void)r.sensor_emulator->send_error(can::kCanErrRestarted);
       },
       [](const WireRig& r) { return r.sensor->link_counters().bus_off_events; }, nullptr},
      {"CAN error-frame storm", WireDevice::sensor, "200 error frames/cycle",
       [](WireRig& r) { r.set_error_storm(true); }, [](WireRig& r) { r.set_error_storm(false); },
       [](const WireRig& r) { return r.sensor->link_counters().error_frames; }, nullptr},
      {"silent sensor", WireDevice::sensor, "emulator mute",
       [](WireRig& r) { r.sensor_emulator->faults().mute = true; },
       [](WireRig& r) { r.sensor_emulator->faults().mute = false; },
       [](const WireRig& r) { return r.sensor->counters().no_data; }, nullptr},
      {"frozen gauges", WireDevice::sensor, "gauges not updated", [](WireRig& r) { r.freeze_gauges(true); },
       [](WireRig& r) { r.freeze_gauges(false); }, [](const WireRig& r) { return guard_stale(r, GuardSource::wrench); },
       nullptr},
      {"F/T status bit", WireDevice::sensor, "status supply low",
       [](WireRig& r) { r.sensor_emulator->set_status(static_cast<std::uint16_t>(hal::kFtSupplyLow)); },
       [](WireRig& r) { r.sensor_emulator->set_status(0); },
       [](const WireRig& r) { return r.sensor->counters().fault_samples; }, nullptr},
      {"camera stall", WireDevice::camera, "freeze_stamp",
       [](WireRig& r) { schedule_camera(r, hal::FaultKind::freeze_stamp); }, nullptr,
       [](const WireRig& r) { return r.supervisor->camera_monitor().counters().stalls; },
       [](const WireRig& r) { return r.observer->fault_counters().of(hal::FaultKind::freeze_stamp); },
       kCameraHoldCycles},
      {"camera repeats a frame", WireDevice::camera, "freeze_data",
       [](WireRig& r) { schedule_camera(r, hal::FaultKind::freeze_data); }, nullptr,
       [](const WireRig& r) { return r.supervisor->camera_monitor().counters().frozen; },
       [](const WireRig& r) { return r.observer->fault_counters().of(hal::FaultKind::freeze_data); },
       kCameraHoldCycles},
      {"clock jump", WireDevice::clock, "reading +50 ms", [](WireRig& r) { r.jump_clock(0.05); }, nullptr,
       [](const WireRig& r) { return guard_stale(r, GuardSource::clock); }, nullptr, 1},
  };
}

}  // namespace pliant::hil
