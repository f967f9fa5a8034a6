// Private to the socketcan driver: what the two socket transports share - one record received
// with its SO_TIMESTAMP, the conversion between struct can_frame and CanFrame, errno mapping.
#pragma once

#include <sys/types.h>

#include <cstddef>
#include <cstdint>

#include "pliant/drivers/socketcan/can_transport.hpp"

namespace pliant::drivers::socketcan::detail {

struct Record {
  ssize_t bytes = -1;             ///< record length, 0 at end of stream, -1 on error (err set)
  int err = 0;                    ///< errno when bytes < 0
  bool truncated = false;         ///< the record was longer than the buffer
  std::int64_t realtime_ns = -1;  ///< SO_TIMESTAMP, -1 if none
};

/// recvmsg(MSG_DONTWAIT) of one record into buf[capacity] with its receive timestamp.
Record receive_record(int fd, void* buf, std::size_t capacity) noexcept;

/// A 16-byte struct can_frame record -> CanFrame; false if len > 8.
bool frame_from_record(const void* record, CanFrame& out) noexcept;
/// CanFrame -> 16-byte struct can_frame record (dlc clamped to 8).
void record_from_frame(const CanFrame& frame, void* record) noexcept;

/// SO_TIMESTAMP on; false (errno kept) on failure.
bool enable_timestamps(int fd) noexcept;
/// O_NONBLOCK and FD_CLOEXEC on; false (errno kept) on failure.
bool make_nonblocking(int fd) noexcept;

}  // namespace pliant::drivers::socketcan::detail
