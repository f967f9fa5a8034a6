// pliant hal: a parallel two-jaw gripper (e.g. Robotiq 2F-85/140 over Modbus; device facts and
// their sources in docs/hal.md and docs/drivers/modbus.md, "Device facts we rely on").
//
// Units: width_m is the pad-to-pad opening (m), speeds m/s, forces N, current A.
// Reading: the latest state (width, grip force or motor current, status bits), stamped on the
//   device's clock. read() returns ok with a new sample, no_data when the device has not
//   produced one since the last read, or a transport error: timeout (a Modbus poll got no
//   answer), disconnected, io_error. A fault the gripper reports itself comes as status bits
//   (kGripperFaultCodeMask, Robotiq's gFLT), not as an error status.
// Commands: write() latches one command; the device executes it asynchronously (it returns
//   as soon as the command is accepted or refused, never waiting for the motion).
//   move  - go to width_m at speed_m_per_s, stopping early if the grip force reaches force_n
//           (then kGripperObjectDetected, Robotiq's gOBJ = 2).
//   stop  - freeze: stop every motion and hold the current width.
//   open  - go to the largest width at speed_m_per_s (force and width ignored).
//   Values are clamped into limits() (a Robotiq takes bytes 0..255 anyway); non-finite or
//   non-positive speed / force, or a non-finite width, are refused with invalid_argument.
// Real-time safety: read and write are bounded, non-blocking, allocation-free, noexcept.
#pragma once

#include <cstdint>
#include <limits>

#include "pliant/hal/device.hpp"

namespace pliant::hal {

/// Status bits of GripperReading::header.status_bits.
inline constexpr std::uint32_t kGripperActivated = 1u << 0;       ///< ready to move (Robotiq gSTA = 3)
inline constexpr std::uint32_t kGripperMoving = 1u << 1;          ///< a move is in progress
inline constexpr std::uint32_t kGripperObjectDetected = 1u << 2;  ///< stopped by contact force while closing
inline constexpr std::uint32_t kGripperAtTarget = 1u << 3;        ///< reached the requested width
inline constexpr std::uint32_t kGripperFaultCodeShift = 8;        ///< bits 8-15: fault code, 0 = none (gFLT)
inline constexpr std::uint32_t kGripperFaultCodeMask = 0xffu << kGripperFaultCodeShift;
/// The bits that mean a fault: a non-zero fault code. Use as GraspGuardConfig::gripper_fault_mask.
inline constexpr std::uint32_t kGripperFaultMask = kGripperFaultCodeMask;

/// Fault codes (Robotiq gFLT values, docs/drivers/modbus.md) for bits 8-15.
inline constexpr std::uint8_t kGripperFaultOverTemperature = 0x08;
inline constexpr std::uint8_t kGripperFaultUnderVoltage = 0x0a;
inline constexpr std::uint8_t kGripperFaultInternal = 0x0c;
inline constexpr std::uint8_t kGripperFaultOverCurrent = 0x0e;

constexpr std::uint8_t gripper_fault_code(std::uint32_t status_bits) noexcept {
  return static_cast<std::uint8_t>((status_bits & kGripperFaultCodeMask) >> kGripperFaultCodeShift);
}

struct GripperReading {
  SampleHeader header;
  double width_m = std::numeric_limits<double>::quiet_NaN();         ///< pad-to-pad opening
  double force_n = std::numeric_limits<double>::quiet_NaN();         ///< grip force (NaN if not sensed)
  double current_a = std::numeric_limits<double>::quiet_NaN();       ///< motor current (NaN if not sensed)
  double target_width_m = std::numeric_limits<double>::quiet_NaN();  ///< the width being moved to
};

enum class GripperCommandKind : std::uint8_t { move, stop, open };

struct GripperCommand {
  GripperCommandKind kind = GripperCommandKind::stop;
  double width_m = std::numeric_limits<double>::quiet_NaN();        ///< move: target opening
  double speed_m_per_s = std::numeric_limits<double>::quiet_NaN();  ///< move, open
  double force_n = std::numeric_limits<double>::quiet_NaN();        ///< move: stop closing at this grip force
};

struct GripperLimits {
  double min_width_m = 0;
  double max_width_m = 0.085;
  double max_speed_m_per_s = 0.15;
  double min_force_n = 0;  ///< a Robotiq's force byte 0 is not zero force (docs/hal.md)
  double max_force_n = 235;
};

class Gripper : public Device {
 public:
  /// The latest sample (see the top of the file). `out` is written only on ok.
  HalStatus read(GripperReading& out) noexcept;
  /// Latches one command (see the top of the file).
  HalStatus write(const GripperCommand& command) noexcept;

  // Helpers over write().
  HalStatus move_to(double width_m, double speed_m_per_s, double force_n) noexcept;
  HalStatus freeze() noexcept;
  HalStatus open(double speed_m_per_s) noexcept;

  /// Valid once configured.
  virtual GripperLimits limits() const noexcept = 0;

 protected:
  Gripper() noexcept : Device(kGripperFaultMask) {}
  virtual HalStatus on_read(GripperReading& out) noexcept = 0;
  /// Receives a validated command, clamped into limits().
  virtual HalStatus on_write(const GripperCommand& command) noexcept = 0;
};

}  // namespace pliant::hal
