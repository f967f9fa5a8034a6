// pliant modbus driver: the Robotiq 2F-85 / 2F-140 register map as pure functions (no I/O).
//
// Register map (Robotiq 2F-85 & 2F-140 Instruction Manual, section 4; sources per fact in
// docs/drivers/modbus.md, "Device facts we rely on"):
//   command  3 holding registers at 0x03E8, written with FC16 ("robot output")
//   status   3 registers at 0x07D0, read with FC04 (current manuals) or FC03 (2016 manual,
//            older drivers) ("robot input")
// Each register carries two bytes, the first byte in the high half (big-endian):
//
//   byte | command (robot output)                 | status (robot input)
//   -----+----------------------------------------+--------------------------------------------
//    0   | action: rACT b0, rGTO b3, rATR b4,     | gripper status: gACT b0, gGTO b3,
//        |         rARD b5                        |                 gSTA b4-5, gOBJ b6-7
//    1   | reserved (0)                           | reserved
//    2   | reserved (0)                           | fault: gFLT b0-3, kFLT b4-7
//    3   | rPR position request, 0 open..255 shut | gPR echo of the position request
//    4   | rSP speed, 0 slowest..255 fastest      | gPO actual position (encoder) 0..255
//    5   | rFR force, 0 weakest..255 strongest    | gCU motor current, about 10 mA per count
//
// gSTA: 0 reset / auto-release, 1 activating, 3 activated. gOBJ (meaningful only when gGTO = 1):
// 0 moving, 1 stopped by contact while opening, 2 stopped by contact while closing (object
// detected), 3 at the requested position. gFLT: 0 none, 0x05 action delayed (activate first),
// 0x07 activation bit not set, 0x08 over-temperature, 0x0A under-voltage, 0x0B auto-release in
// progress, 0x0C internal fault, 0x0D activation fault, 0x0E over-current, 0x0F auto-release
// complete. A force byte of 0 is the gripper's smallest force, not zero force.
//
// Mapping onto pliant::hal::GripperReading (status_bits, hal/include/pliant/hal/gripper.hpp):
//   kGripperActivated       gACT = 1 and gSTA = 3
//   kGripperMoving          gGTO = 1 and gOBJ = 0
//   kGripperObjectDetected  gGTO = 1 and gOBJ = 2
//   kGripperAtTarget        gGTO = 1 and gOBJ = 3
//   bits 8-15 (fault code)  status byte 2 verbatim: gFLT in bits 8-11, kFLT in bits 12-15, so
//                           gripper_fault_code() equals gFLT (e.g. 0x0E over-current) when the
//                           controller fault kFLT is 0, and any non-zero byte is a fault.
//   width_m                 from gPO through Robotiq2fScaling; target_width_m from gPR
//   current_a               gCU * 0.01 A; force_n stays NaN (the gripper does not sense force)
//
// Scaling: position byte p maps linearly to the pad-to-pad width
//   width_m = stroke_m * (closed_byte - p) / (closed_byte - open_byte), clamped to [0, stroke_m]
// with open_byte = 0, closed_byte = 255 by default; a calibrated gripper's encoder typically
// spans about 3..230 (Robotiq KB), which a user can enter as open_byte / closed_byte. Speed and
// force bytes map linearly onto [min, max] of the model (2F-85: 20..150 mm/s, 20..235 N;
// 2F-140: 30..250 mm/s, 10..125 N; datasheet figures, not verified on hardware here).
//
// Every function is pure, allocation-free, noexcept and total: any register values decode,
// any double (NaN included) encodes to a byte without undefined behaviour.
#pragma once

#include <cstdint>

#include "pliant/hal/gripper.hpp"
#include "pliant/hal/status.hpp"

namespace pliant::drivers::modbus::robotiq2f {

inline constexpr int kCommandRegister = 0x03e8;  ///< first command register (FC16)
inline constexpr int kStatusRegister = 0x07d0;   ///< first status register (FC04, FC03)
inline constexpr int kRegisterCount = 3;         ///< both blocks are 3 registers (6 bytes)
inline constexpr int kDefaultSlaveId = 9;
inline constexpr int kDefaultBaud = 115200;  ///< 8N1

// Action request bits (command byte 0).
inline constexpr std::uint8_t kActionActivate = 1u << 0;          ///< rACT
inline constexpr std::uint8_t kActionGoTo = 1u << 3;              ///< rGTO
inline constexpr std::uint8_t kActionAutoRelease = 1u << 4;       ///< rATR
inline constexpr std::uint8_t kActionReleaseDirection = 1u << 5;  ///< rARD

// gSTA and gOBJ values.
inline constexpr std::uint8_t kStaReset = 0;
inline constexpr std::uint8_t kStaActivating = 1;
inline constexpr std::uint8_t kStaActivated = 3;
inline constexpr std::uint8_t kObjMoving = 0;
inline constexpr std::uint8_t kObjContactOpening = 1;
inline constexpr std::uint8_t kObjContactClosing = 2;
inline constexpr std::uint8_t kObjAtPosition = 3;

// gFLT values not already in hal/gripper.hpp.
inline constexpr std::uint8_t kFaultActionDelayed = 0x05;
inline constexpr std::uint8_t kFaultActivationBitNotSet = 0x07;
inline constexpr std::uint8_t kFaultAutoReleaseInProgress = 0x0b;
inline constexpr std::uint8_t kFaultActivation = 0x0d;
inline constexpr std::uint8_t kFaultAutoReleaseComplete = 0x0f;

/// One command block (robot output bytes 0, 3, 4, 5; bytes 1 and 2 are always written 0).
struct Command {
  std::uint8_t action = 0;    ///< kAction* bits
  std::uint8_t position = 0;  ///< rPR
  std::uint8_t speed = 0;     ///< rSP
  std::uint8_t force = 0;     ///< rFR
};

/// One status block, field by field.
struct Status {
  std::uint8_t gact = 0;              ///< 0/1
  std::uint8_t ggto = 0;              ///< 0/1
  std::uint8_t gsta = 0;              ///< 0..3
  std::uint8_t gobj = 0;              ///< 0..3
  std::uint8_t gflt = 0;              ///< 0..15
  std::uint8_t kflt = 0;              ///< 0..15
  std::uint8_t position_request = 0;  ///< gPR
  std::uint8_t position = 0;          ///< gPO
  std::uint8_t current = 0;           ///< gCU, ~10 mA per count
  std::uint8_t reserved = 0;          ///< byte 1 as read (not interpreted)
};

/// Command -> the 3 registers to write at kCommandRegister:
/// {action << 8, position, speed << 8 | force}.
void encode_command(const Command& command, std::uint16_t registers[kRegisterCount]) noexcept;
/// The inverse (used by the emulator; reserved bytes 1 and 2 are ignored).
Command decode_command(const std::uint16_t registers[kRegisterCount]) noexcept;

/// The 3 status registers -> Status. Total: every input decodes (byte 1 goes to `reserved`).
Status decode_status(const std::uint16_t registers[kRegisterCount]) noexcept;
/// The inverse (used by the emulator). Fields are masked to their bit widths.
void encode_status(const Status& status, std::uint16_t registers[kRegisterCount]) noexcept;

/// True when the gripper finished its activation (gACT = 1, gSTA = 3).
constexpr bool is_activated(const Status& s) noexcept { return s.gact == 1 && s.gsta == kStaActivated; }

/// The hal status bits of `s` (see the mapping at the top of the file).
std::uint32_t status_bits(const Status& s) noexcept;

/// A model's geometry and ranges. Valid when stroke_m > 0, open_byte != closed_byte, and each
/// range is finite with 0 <= min < max (speed range strictly positive at the top).
struct Scaling {
  double stroke_m = 0.085;           ///< width at open_byte (2F-85: 0.085, 2F-140: 0.140)
  std::uint8_t open_byte = 0;        ///< position byte of the widest opening
  std::uint8_t closed_byte = 255;    ///< position byte of the closed fingers (width 0)
  double min_speed_m_per_s = 0.020;  ///< at speed byte 0
  double max_speed_m_per_s = 0.150;  ///< at speed byte 255
  double min_force_n = 20;           ///< at force byte 0 (not zero force)
  double max_force_n = 235;          ///< at force byte 255
};

/// invalid_argument when the scaling breaks the rules above, else ok.
hal::HalStatus validate(const Scaling& scaling) noexcept;

/// The width (m) for position byte `p`, clamped to [0, stroke_m].
double position_to_width(std::uint8_t p, const Scaling& scaling) noexcept;
/// The nearest position byte for width_m (clamped to [0, stroke_m]); NaN gives open_byte.
std::uint8_t width_to_position(double width_m, const Scaling& scaling) noexcept;
/// Speed byte for speed_m_per_s (clamped to the range; NaN gives 0, the slowest).
std::uint8_t speed_to_byte(double speed_m_per_s, const Scaling& scaling) noexcept;
/// Speed (m/s) of speed byte `b`.
double byte_to_speed(std::uint8_t b, const Scaling& scaling) noexcept;
/// Force byte for force_n (clamped to the range; NaN gives 0, the weakest).
std::uint8_t force_to_byte(double force_n, const Scaling& scaling) noexcept;
/// Force limit (N) of force byte `b`.
double byte_to_force(std::uint8_t b, const Scaling& scaling) noexcept;
/// Motor current (A) of a gCU byte: 0.01 A per count.
constexpr double current_from_byte(std::uint8_t b) noexcept { return 0.01 * static_cast<double>(b); }

/// Fills the measured fields and the status bits of `out` from `s` (stamp and sequence are
/// left to the caller; force_n is set to NaN).
void to_reading(const Status& s, const Scaling& scaling, hal::GripperReading& out) noexcept;

}  // namespace pliant::drivers::modbus::robotiq2f
