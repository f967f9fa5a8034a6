// pliant hal mocks: fault scripts, a small text format for FaultSchedules.
//
// One event per line:
//     t_s  kind  device  duration_s  [value]
//   t_s         start on the devices' clock, s (a finite decimal number)
//   kind        a fault_kind_name: drop freeze_data freeze_stamp nan stamp_jump fault_bits
//               occlude disconnect bus_off timeout
//   device      gripper | ft | observer | color | depth
//   duration_s  finite, > 0
//   value       optional kind parameter (fault_schedule.hpp): a decimal number, or for
//               fault_bits an integer (decimal or 0x-hex) in [0, 2^32)
// Fields are separated by spaces or tabs; '#' starts a comment that runs to the end of the
// line; blank lines are skipped; lines end in LF or CRLF. A kind the device cannot have (e.g.
// bus_off on the gripper) is an error. Example:
//     # Modbus timeout for 50 ms, then a CAN bus-off
//     1.20 timeout gripper 0.05
//     1.50 bus_off ft      0.02
//     2.00 fault_bits gripper 0.1 0x0e00
//
// The parser reads exactly `length` bytes (no terminator needed), never allocates, never
// throws, and on any error reports the 1-based line and column and a fixed message, leaving
// the script holding the events of the lines before it.
#pragma once

#include <cstddef>
#include <cstdint>

#include "pliant/hal/mock/fault_schedule.hpp"

namespace pliant::hal {

enum class FaultDevice : std::uint8_t { gripper = 0, force_torque, observer, color_camera, depth_camera, count };
inline constexpr int kFaultDeviceCount = static_cast<int>(FaultDevice::count);

/// Script names: "gripper", "ft", "observer", "color", "depth".
const char* fault_device_name(FaultDevice device) noexcept;
/// The FaultKind bits a device accepts (kGripperFaults, ...).
std::uint32_t fault_device_kinds(FaultDevice device) noexcept;

struct FaultScript {
  FaultSchedule schedules[kFaultDeviceCount];
  const FaultSchedule& of(FaultDevice device) const noexcept { return schedules[static_cast<int>(device)]; }
  int events() const noexcept;
};

struct FaultScriptError {
  int line = 0;    ///< 1-based; 0 when there is no error
  int column = 0;  ///< 1-based byte column of the offending field
  const char* message = "";
};

/// Parses `text` ([length] bytes) into `script` (cleared first). ok, or invalid_argument /
/// capacity_exceeded (more than kFaultCapacity events for one device) with `error` set.
HalStatus parse_fault_script(const char* text, std::size_t length, FaultScript& script,
                             FaultScriptError& error) noexcept;

}  // namespace pliant::hal
