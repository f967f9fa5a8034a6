// pliant socketcan driver: the CAN transport the sensor classes talk through.
//
// Two implementations:
//   RawCanTransport       (raw_can_transport.hpp) an AF_CAN raw socket bound to one interface
//                         (can0, vcan0, ...): the real bus.
//   SeqpacketCanTransport (seqpacket_transport.hpp) an AF_UNIX SOCK_SEQPACKET socket carrying
//                         one 16-byte struct can_frame per record: CI and HIL rigs without
//                         AF_CAN, with an emulated sensor on the other end.
//
// Contract
// - open() acquires the socket and applies the receive filter; it may be called again after
//   close() or after a disconnect (that is how a device reconnects). It makes system calls but
//   allocates nothing in user space and never blocks.
// - send() and receive() never block: a full transmit queue is `busy`, an empty receive queue
//   is `empty`. Both are allocation-free, noexcept and O(1) (one system call).
// - receive() delivers data frames and, on transports that have them, error frames (kCanErrFlag
//   in the id; see can_error.hpp). A record that is not a valid CAN frame is `malformed` and
//   consumed (the next call reads the next record). `disconnected` means the link is gone (the
//   peer closed, the interface vanished or went down); the transport is then closed.
// - Receive timestamps: CanRxInfo::realtime_ns is the kernel's receive time (SO_TIMESTAMP,
//   CLOCK_REALTIME, microsecond resolution) or -1 when the kernel gave none.
// - The receive filter (set_receive_filter) lists the 11-bit IDs a device wants; a transport
//   that can filter in the kernel (AF_CAN) drops the rest there, others deliver everything and
//   the device counts what it does not recognise.
// Thread safety: none; a transport is driven by one thread (the device's).
// Ownership: a device holds a reference to its transport; the caller keeps it alive and does
// not share it between devices.
#pragma once

#include <cstddef>
#include <cstdint>

#include "pliant/drivers/socketcan/can_frame.hpp"
#include "pliant/hal/status.hpp"

namespace pliant::drivers::socketcan {

enum class [[nodiscard]] CanIo : std::uint8_t{
    ok = 0,        ///< one frame sent or received
    empty,         ///< receive: nothing queued (not an error)
    busy,          ///< send: the transmit queue is full (ENOBUFS/EAGAIN); the frame was not sent
    malformed,     ///< receive: a record that is not a CAN frame was consumed and discarded
    disconnected,  ///< the link is gone; the transport closed itself
    io_error,      ///< any other system error (see last_errno())
};

const char* can_io_name(CanIo io) noexcept;

struct CanRxInfo {
  std::int64_t realtime_ns = -1;  ///< kernel receive time, CLOCK_REALTIME ns; -1: unknown
};

inline constexpr std::size_t kMaxCanFilterIds = 16;

class CanTransport {
 public:
  virtual ~CanTransport() = default;
  CanTransport(const CanTransport&) = delete;
  CanTransport& operator=(const CanTransport&) = delete;

  /// (Re)opens the link. ok, or: unsupported (no AF_CAN in this kernel), disconnected (the
  /// interface or peer is not there now: try again later), invalid_argument (bad name or
  /// address), io_error (see last_errno()). Opening an open transport is ok and changes nothing.
  virtual hal::HalStatus open() noexcept = 0;
  /// Releases the socket. Safe to call when closed.
  virtual void close() noexcept = 0;
  virtual bool is_open() const noexcept = 0;
  virtual CanIo send(const CanFrame& frame) noexcept = 0;
  virtual CanIo receive(CanFrame& frame, CanRxInfo& info) noexcept = 0;

  /// The IDs to receive (standard 11-bit IDs, at most kMaxCanFilterIds; count 0: everything).
  /// Takes effect at the next open(). invalid_argument (filter unchanged) for too many IDs or
  /// an ID above 0x7ff.
  hal::HalStatus set_receive_filter(const std::uint32_t* ids, std::size_t count) noexcept;
  std::size_t filter_count() const noexcept { return filter_count_; }
  const std::uint32_t* filter_ids() const noexcept { return filter_ids_; }

  /// errno of the last failed system call (0 if none yet), for log messages.
  int last_errno() const noexcept { return last_errno_; }

 protected:
  CanTransport() = default;
  void set_errno(int e) noexcept { last_errno_ = e; }

 private:
  std::uint32_t filter_ids_[kMaxCanFilterIds] = {};
  std::size_t filter_count_ = 0;
  int last_errno_ = 0;
};

}  // namespace pliant::drivers::socketcan
