#include "wire_rig.hpp"

#include <cmath>
#include <limits>
#include <string>

#include "pliant/drivers/socketcan/can_error.hpp"

namespace pliant::hil {
namespace {

namespace mb = drivers::modbus;
namespace can = drivers::socketcan;

mb::ModbusEmulatorConfig emulator_config() {
  mb::ModbusEmulatorConfig c;
  c.transport = mb::EmulatorTransport::tcp;
  c.gripper.activation_time_s = 0.1;
  return c;
}

can::AtiEmulatorConfig sensor_emulator_config() {
  can::AtiEmulatorConfig c;
  c.calibration = wire_calibration();
  return c;
}

}  // namespace

SupervisorConfig wire_supervisor_config(const HilObject& object, const WireOptions& options) {
  SupervisorConfig c = hil_supervisor_config(object, options.base);
  const mb::robotiq2f::Scaling scaling;  // the 2F-85
  c.guard.max_strain = (1 - options.strain_margin) * object.max_strain;
  // The 2F-85's slowest and fastest speeds (the HAL HIL squeezes at 4 mm/s, below its range).
  c.close_speed_m_per_s = scaling.min_speed_m_per_s;
  c.approach_speed_m_per_s = scaling.max_speed_m_per_s;
  // The width comes in position counts: the approach target is met within one count.
  c.approach_tolerance_m = scaling.stroke_m / 255.0;
  // A Robotiq's status block has no noise: a gripper at rest repeats it bit for bit.
  c.gripper_monitor.frozen_repeats = 0;
  return c;
}

WireRig::WireRig(const HilObject& object, const WireOptions& options)
    : gripper_emulator(emulator_config()),
      options_(options),
      gauges_(wire_calibration(), options.gauge_noise_counts, options.base.seed + 3) {
  status_ = start_plant(object);
  if (status_ != hal::HalStatus::ok) return;
  for (auto start : {&WireRig::start_gripper, &WireRig::start_sensor, &WireRig::start_camera}) {
    status_ = (this->*start)();
    if (status_ != hal::HalStatus::ok) return;
  }
  finger_sensor = std::make_unique<RecordingForceTorque>(*sensor);
  finger_gripper = std::make_unique<FingerForceGripper>(*gripper, *finger_sensor, 0);
  for (hal::Device* d : {static_cast<hal::Device*>(finger_gripper.get()),
                         static_cast<hal::Device*>(finger_sensor.get()), static_cast<hal::Device*>(observer.get())}) {
    status_ = d->configure();
    if (status_ != hal::HalStatus::ok) return;
  }
  feed_sensor();
  supervisor = std::make_unique<Supervisor>(*finger_gripper, *finger_sensor, *observer, clock,
                                            wire_supervisor_config(object, options_));
  status_ = supervisor->start();
}

WireRig::~WireRig() {
  // The emulator's server thread asks the finger about the plant: stop it before they go.
  gripper_emulator.set_object_model(nullptr);
  gripper_emulator.stop();
}

hal::HalStatus WireRig::start_plant(const HilObject& object) {
  hal::SimulatedGraspConfig sim;
  sim.object = object.object;
  sim.period_s = period_s();
  sim.max_width_m = mb::robotiq2f::Scaling{}.stroke_m;  // the fingers start at the 2F-85's stroke
  return plant.configure(sim);
}

hal::HalStatus WireRig::start_gripper() {
  std::string error;
  if (!gripper_emulator.start(&error)) return hal::HalStatus::io_error;
  gripper_emulator.set_object_model(&finger);
  mb::RobotiqGripperConfig c;
  c.link.transport = mb::ModbusTransport::tcp;
  c.link.host = "127.0.0.1";
  c.link.port = gripper_emulator.port();
  c.link.response_timeout_s = options_.modbus_timeout_s;
  c.link.reconnect_interval_s = options_.reconnect_interval_s;
  c.reset_hold_s = 0.02;
  gripper = std::make_unique<mb::RobotiqGripper>(clock, c);
  return hal::HalStatus::ok;
}

hal::HalStatus WireRig::start_sensor() {
  const hal::HalStatus s = can::SeqpacketCanTransport::make_pair(device_end, sensor_end);
  if (s != hal::HalStatus::ok) return s;
  sensor_emulator = std::make_unique<can::AtiNetCanEmulator>(sensor_end, sensor_emulator_config());
  can::AtiNetCanConfig c;
  c.link.use_receive_timestamps = false;  // stamps on the stepped clock
  c.link.reconnect_interval_s = options_.reconnect_interval_s;
  sensor = std::make_unique<can::AtiNetCanForceTorque>(device_end, clock, c);
  return hal::HalStatus::ok;
}

hal::HalStatus WireRig::start_camera() {
  hal::MockParticleObserverConfig oc;
  oc.period_s = 1.0 / options_.base.camera_rate_hz;
  oc.noise_m = options_.base.camera_noise_m;
  oc.seed = options_.base.seed + 2;
  observer = std::make_unique<hal::MockParticleObserver>(plant, clock, oc);
  return hal::HalStatus::ok;
}

void WireRig::follow_fingers() noexcept {
  // The jaws follow the fingers within the period (the plant's jaw speed is the 2F-85's top speed).
  plant.command_move(gripper_emulator.gripper().width_m, plant.config().jaw_max_speed_m_per_s,
                     std::numeric_limits<double>::infinity());
  plant.sync();
}

void WireRig::feed_sensor() noexcept {
  if (!gauges_frozen_) {
    const double wrench[6] = {plant.grip_force_n(), 0, 0, 0, 0, 0};
    std::int16_t g[6];
    gauges_.gauges(wrench, g);
    sensor_emulator->set_gauges(g);
  }
  if (storm_) {
    const std::uint8_t warning[8] = {0, can::kCanCtrlRxWarning, 0, 0, 0, 0, 0, 0};
    for (int i = 0; i < options_.storm_frames; ++i) (void)sensor_emulator->send_error(can::kCanErrController, warning);
  }
  (void)sensor_emulator->service();
}

bool WireRig::held_at_safe_width(const GraspGuardOutput& out) const noexcept {
  namespace r2f = mb::robotiq2f;
  const r2f::Status& s = gripper->last_status();
  const r2f::Scaling& scaling = gripper->config().scaling;
  const bool at_target = s.ggto == 1 && s.gobj == r2f::kObjAtPosition;
  const double half_count = 0.5 * scaling.stroke_m / 255.0;
  return out.in_contact && at_target && std::isfinite(out.safe_width_m) &&
         std::abs(r2f::position_to_width(s.position_request, scaling) - out.safe_width_m) <= half_count;
}

const CycleReport& WireRig::step() {
  ++cycles_;
  // Whole periods from the start, so that stamps land on the sample grid.
  (void)clock.set(10.0 + static_cast<double>(cycles_) * period_s() + clock_offset_s_);
  gripper_emulator.advance(period_s());
  follow_fingers();
  feed_sensor();
  return supervisor->cycle();
}

}  // namespace pliant::hil
