// The wire HIL rig: the HIL supervisor (tests/hil/hil_supervisor.hpp) closing a Robotiq 2F-85
// over Modbus TCP and reading an ATI NETCANOEM finger sensor over CAN, both through pliant's
// real drivers and their emulators, on the same simulated soft object as the HAL HIL.
//
// Parts (one rig per grasp):
//   clock     ManualClock, stepped one control period per cycle (1 kHz)
//   plant     SimulatedGrasp (the MSM object between two jaws), the fingers start fully open
//   gripper   ModbusEmulator (its server thread on 127.0.0.1, a free port) whose Robotiq model
//             squeezes the plant (PlantFinger) <- Modbus TCP -> RobotiqGripper
//   sensor    AtiNetCanEmulator with gauges from the plant's grip force (FingerGauges) <- a
//             SeqpacketCanTransport pair -> AtiNetCanForceTorque (calibration read from the
//             emulator at setup)
//   camera    MockParticleObserver on the plant (30 Hz, 30 um noise), as in the HAL HIL: the
//             supervisor needs every particle's 3D position, interior ones included, which no
//             camera image shows (docs/hil_wire.md)
//   supervisor  sees the gripper through FingerForceGripper (grip force from the finger
//             sensor: a Robotiq senses none) and the sensor through RecordingForceTorque
// One step: the clock moves one period; the Robotiq model moves its fingers for that period
// under the command it latched; the plant's jaws follow the fingers and the object relaxes; the
// sensor's gauges are set from the plant's grip force and the sensor emulator answers the
// driver's outstanding poll; then the supervisor runs one cycle (its Modbus transactions are
// answered by the emulator's thread from the model's state of this period).
// Faults the rig injects itself (the emulators' own knobs are reached through the members):
// frozen gauges, a storm of CAN error frames, and a jump of the clock's reading.
#pragma once

#include <cstdint>
#include <memory>

#include "finger_force.hpp"
#include "finger_gauges.hpp"
#include "hil_rig.hpp"
#include "plant_finger.hpp"
#include "pliant/drivers/modbus/emulator/modbus_emulator.hpp"
#include "pliant/drivers/modbus/robotiq_gripper.hpp"
#include "pliant/drivers/socketcan/ati_netcanoem_sensor.hpp"
#include "pliant/drivers/socketcan/emulator/ati_netcanoem_emulator.hpp"
#include "pliant/drivers/socketcan/seqpacket_transport.hpp"

namespace pliant::hil {

/// The guard's design margin on the wire: the HAL HIL's 5 % covers a contact width taken from one
/// 5 um-noise sample; a Robotiq reports its width in position counts of 0.33 mm, and both the
/// contact width and the current width carry up to half a count of rounding.
inline constexpr double kWireStrainMargin = 0.05;

struct WireOptions {
  RigOptions base;  ///< rates, camera, prediction table, seed (pregrasp_gap_m unused: fingers start open)
  double strain_margin = kWireStrainMargin;
  double modbus_timeout_s = 0.5;       ///< a Modbus answer's budget (wall time: the emulator runs in a thread)
  double reconnect_interval_s = 0.01;  ///< Modbus and CAN, on the stepped clock
  double gauge_noise_counts = 3;       ///< sd of each strain gauge
  int storm_frames = 200;              ///< error frames per cycle while a storm runs: over 2 reads' budget (64 each)
};

/// The HIL supervisor configuration adapted to the real devices (see docs/hil_wire.md).
SupervisorConfig wire_supervisor_config(const HilObject& object, const WireOptions& options);

class WireRig {
 public:
  WireRig(const HilObject& object, const WireOptions& options);
  ~WireRig();
  WireRig(const WireRig&) = delete;
  WireRig& operator=(const WireRig&) = delete;

  /// ok when every part started; otherwise the first failure (the rig is then unusable).
  hal::HalStatus status() const noexcept { return status_; }
  /// One control period (see the top of the file).
  const CycleReport& step();
  double period_s() const noexcept { return 1.0 / options_.base.rate_hz; }
  std::int64_t cycles() const noexcept { return cycles_; }

  /// True when the fingers stand still at the position the guard's safe width commands (to
  /// within half a position count): the guard's bound, not its verdict, stopped the squeeze. On
  /// a Robotiq the safe width goes out rounded to a count; when it rounds open the closure stays
  /// short of the safe closure and the verdict can stay ok.
  bool held_at_safe_width(const GraspGuardOutput& out) const noexcept;

  // Faults of the rig's own.
  void freeze_gauges(bool frozen) noexcept { gauges_frozen_ = frozen; }
  void set_error_storm(bool on) noexcept { storm_ = on; }
  /// The clock's reading jumps ahead by jump_s at the next step (physical time does not).
  void jump_clock(double jump_s) noexcept { clock_offset_s_ += jump_s; }

  hal::ManualClock clock{10.0};
  hal::SimulatedGrasp plant{clock};
  PlantFinger finger{plant};
  drivers::modbus::ModbusEmulator gripper_emulator;
  drivers::socketcan::SeqpacketCanTransport sensor_end;
  drivers::socketcan::SeqpacketCanTransport device_end;
  std::unique_ptr<drivers::socketcan::AtiNetCanEmulator> sensor_emulator;
  std::unique_ptr<drivers::modbus::RobotiqGripper> gripper;
  std::unique_ptr<drivers::socketcan::AtiNetCanForceTorque> sensor;
  std::unique_ptr<RecordingForceTorque> finger_sensor;
  std::unique_ptr<FingerForceGripper> finger_gripper;
  std::unique_ptr<hal::MockParticleObserver> observer;
  std::unique_ptr<Supervisor> supervisor;

 private:
  hal::HalStatus start_plant(const HilObject& object);
  hal::HalStatus start_gripper();
  hal::HalStatus start_sensor();
  hal::HalStatus start_camera();
  void follow_fingers() noexcept;
  void feed_sensor() noexcept;

  WireOptions options_;
  FingerGauges gauges_;
  hal::HalStatus status_ = hal::HalStatus::invalid_argument;
  std::int64_t cycles_ = 0;
  double clock_offset_s_ = 0;
  bool gauges_frozen_ = false;
  bool storm_ = false;
};

}  // namespace pliant::hil
