// pliant socketcan driver: what a SocketCAN error frame says (Linux can/error.h; see
// docs/drivers/socketcan.md, "Device facts we rely on").
//
// The kernel sends error frames to sockets that asked for them (CAN_RAW_ERR_FILTER). One frame
// has kCanErrFlag in its id, class bits in id bits 0-9, and details in data (DLC 8):
//   0x001 TX timeout        0x002 lost arbitration (data[0] = bit)   0x004 controller (data[1])
//   0x008 protocol violation (data[2], data[3])   0x010 transceiver (data[4])   0x020 no ACK
//   0x040 bus-off           0x080 bus error (may flood)   0x100 controller restarted
//   0x200 error counters valid (data[6] = TX, data[7] = RX error counter)
// data[1] controller bits: 0x01 RX overflow, 0x02 TX overflow, 0x04 RX warning, 0x08 TX warning,
//   0x10 RX passive, 0x20 TX passive, 0x40 back to error-active.
//
// decode_can_error() is pure: no I/O, no allocation, noexcept, O(1). Bytes beyond the frame's
// dlc read as zero, so a short (malformed) error frame still yields its class bits.
#pragma once

#include <cstdint>

#include "pliant/drivers/socketcan/can_frame.hpp"

namespace pliant::drivers::socketcan {

// Error classes (id bits) and controller flags (data[1]), named after can/error.h.
inline constexpr std::uint32_t kCanErrTxTimeout = 0x001u;
inline constexpr std::uint32_t kCanErrLostArbitration = 0x002u;
inline constexpr std::uint32_t kCanErrController = 0x004u;
inline constexpr std::uint32_t kCanErrProtocol = 0x008u;
inline constexpr std::uint32_t kCanErrTransceiver = 0x010u;
inline constexpr std::uint32_t kCanErrNoAck = 0x020u;
inline constexpr std::uint32_t kCanErrBusOff = 0x040u;
inline constexpr std::uint32_t kCanErrBusError = 0x080u;
inline constexpr std::uint32_t kCanErrRestarted = 0x100u;
inline constexpr std::uint32_t kCanErrCounters = 0x200u;
inline constexpr std::uint32_t kCanErrClassMask = 0x1fffffffu;  ///< CAN_ERR_MASK: every class

inline constexpr std::uint8_t kCanCtrlRxOverflow = 0x01;
inline constexpr std::uint8_t kCanCtrlTxOverflow = 0x02;
inline constexpr std::uint8_t kCanCtrlRxWarning = 0x04;
inline constexpr std::uint8_t kCanCtrlTxWarning = 0x08;
inline constexpr std::uint8_t kCanCtrlRxPassive = 0x10;
inline constexpr std::uint8_t kCanCtrlTxPassive = 0x20;
inline constexpr std::uint8_t kCanCtrlActive = 0x40;

/// Default error subscription: every class except bus errors, which can flood the socket
/// (one frame per bad bit on a noisy bus) and add nothing the other classes do not say.
inline constexpr std::uint32_t kDefaultCanErrorMask = kCanErrClassMask & ~kCanErrBusError;

struct CanErrorReport {
  std::uint32_t classes = 0;        ///< the class bits above
  std::uint8_t controller = 0;      ///< data[1] when kCanErrController is set, else 0
  std::uint8_t protocol_type = 0;   ///< data[2] when kCanErrProtocol is set, else 0
  std::uint8_t protocol_where = 0;  ///< data[3] when kCanErrProtocol is set, else 0
  std::uint8_t transceiver = 0;     ///< data[4] when kCanErrTransceiver is set, else 0
  std::uint8_t tx_errors = 0;       ///< data[6] when kCanErrCounters is set, else 0
  std::uint8_t rx_errors = 0;       ///< data[7] when kCanErrCounters is set, else 0

  bool bus_off() const noexcept { return (classes & kCanErrBusOff) != 0; }
  /// The controller is usable again: it restarted after bus-off, or reports error-active.
  bool recovered() const noexcept {
    return (classes & kCanErrRestarted) != 0 ||
           ((classes & kCanErrController) != 0 && (controller & kCanCtrlActive) != 0);
  }
  /// Received frames were lost in the controller or the socket's queue.
  bool rx_overflow() const noexcept {
    return (classes & kCanErrController) != 0 && (controller & kCanCtrlRxOverflow) != 0;
  }
};

/// Decodes an error frame. False (report untouched) when `frame` is not an error frame.
bool decode_can_error(const CanFrame& frame, CanErrorReport& report) noexcept;

/// An error frame as the kernel would build it (used by the emulators to inject errors).
/// `data` may be null (all zero); dlc is always 8.
CanFrame make_can_error_frame(std::uint32_t classes, const std::uint8_t* data8) noexcept;

}  // namespace pliant::drivers::socketcan
