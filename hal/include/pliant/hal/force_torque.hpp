// pliant hal: a six-axis force/torque sensor (e.g. ATI F/T over a NETCANOEM CAN board,
// Robotous RFT, Robotiq FT 300; device facts in docs/hal.md, docs/drivers/socketcan.md and
// docs/drivers/modbus.md).
//
// Units and frame: wrench = Fx Fy Fz (N), Tx Ty Tz (N m) in the sensor's own frame, tared as
//   the driver was configured (the mocks have no bias).
// read() returns ok with a new sample, no_data when none arrived since the last read, or a
//   transport error: bus_off (the CAN controller is bus-off), timeout (no response to a
//   poll), disconnected, io_error. The sensor's own status word travels in the status bits,
//   mapped onto the ATI NETCANOEM layout below (other sensors map their flags onto it).
// Real-time safety: read is bounded, non-blocking, allocation-free, noexcept.
#pragma once

#include <cstdint>
#include <limits>

#include "pliant/hal/device.hpp"

namespace pliant::hal {

/// Status bits of WrenchReading::header.status_bits: the ATI NETCANOEM status word.
inline constexpr std::uint32_t kFtWatchdogReset = 1u << 0;
inline constexpr std::uint32_t kFtAdcHigh = 1u << 1;
inline constexpr std::uint32_t kFtAdcLow = 1u << 2;
inline constexpr std::uint32_t kFtGroundOutOfRange = 1u << 3;
inline constexpr std::uint32_t kFtSupplyHigh = 1u << 4;
inline constexpr std::uint32_t kFtSupplyLow = 1u << 5;
inline constexpr std::uint32_t kFtBadCalibration = 1u << 6;
inline constexpr std::uint32_t kFtEepromFailure = 1u << 7;
inline constexpr std::uint32_t kFtConfigInvalid = 1u << 8;
inline constexpr std::uint32_t kFtTemperatureHigh = 1u << 11;
inline constexpr std::uint32_t kFtTemperatureLow = 1u << 12;
inline constexpr std::uint32_t kFtCanBusError = 1u << 14;  ///< transport degraded
inline constexpr std::uint32_t kFtAnyError = 1u << 15;
/// Bits 1-7, 11, 12: the reading must not be trusted (GraspGuardConfig::wrench_fault_mask).
inline constexpr std::uint32_t kFtFaultMask = 0x18feu;

struct WrenchReading {
  SampleHeader header;
  double wrench[6] = {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::quiet_NaN(),
                      std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::quiet_NaN(),
                      std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::quiet_NaN()};
};

class ForceTorqueSensor : public Device {
 public:
  /// The latest sample. `out` is written only on ok.
  HalStatus read(WrenchReading& out) noexcept;

 protected:
  ForceTorqueSensor() noexcept : Device(kFtFaultMask) {}
  virtual HalStatus on_read(WrenchReading& out) noexcept = 0;
};

}  // namespace pliant::hal
