// pliant hal: the status code every device call returns.
//
// Contract
// - Lifecycle calls (configure, start, stop, cleanup), read and write return a HalStatus;
//   nothing on the read/write path throws. HalStatus::ok is zero.
// - `no_data` is not an error: a non-blocking read found nothing new since the last read.
// - The transport errors (disconnected, timeout, bus_off, io_error) and device_fault are the
//   faults a safety supervisor must act on; every one is also counted in DeviceCounters.
#pragma once

#include <cstdint>

namespace pliant::hal {

enum class [[nodiscard]] HalStatus : std::uint8_t{
    ok = 0,
    no_data,            ///< read: nothing new since the last read (not an error)
    wrong_state,        ///< not allowed in the current lifecycle state (e.g. read before start)
    invalid_argument,   ///< a configuration value or command out of its documented range
    unsupported,        ///< the device does not offer this (e.g. a fault kind it cannot have)
    capacity_exceeded,  ///< a fixed capacity is full, or configure could not allocate
    disconnected,       ///< the device is unreachable; reads fail until it is back
    timeout,            ///< no response within the transport's timeout (e.g. a Modbus poll)
    bus_off,            ///< the CAN controller went bus-off
    device_fault,       ///< the device reports a fault that stops it (see its status bits)
    io_error,           ///< any other transport error
};

/// Short, stable name ("ok", "no_data", "bus_off", ...), for logs.
const char* hal_status_name(HalStatus status) noexcept;

/// True for the transport and device errors (disconnected .. io_error).
constexpr bool is_fault(HalStatus status) noexcept {
  return status == HalStatus::disconnected || status == HalStatus::timeout || status == HalStatus::bus_off ||
         status == HalStatus::device_fault || status == HalStatus::io_error;
}

}  // namespace pliant::hal
