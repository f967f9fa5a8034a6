// pliant socketcan driver: CAN frames over an AF_UNIX SOCK_SEQPACKET socket.
//
// Each record is exactly one Linux struct can_frame (16 bytes, host byte order: can_id u32,
// len u8, three reserved bytes, data[8]). SOCK_SEQPACKET keeps record boundaries, so one
// send is one frame and one receive is one frame, as on a raw CAN socket; error frames travel
// as frames with kCanErrFlag, so an emulator on the other end can inject them. This is the
// transport for machines without AF_CAN (CI) and for HIL rigs with an emulated sensor.
//
// Two ways to get a link:
//   make_pair(a, b)      socketpair(): a and b are connected ends; a closed end cannot reopen
//                        (open() then returns disconnected).
//   client(address) + SeqpacketCanListener::listen(address)
//                        the device end connects to a listener; after the peer closes,
//                        open() connects again, so a device can reconnect. `address` is a
//                        filesystem path, or "@name" for Linux's abstract namespace (no file).
// receive(): a record of any size other than 16 bytes, or with len > 8, is `malformed`;
// end of stream (the peer closed) and ECONNRESET are `disconnected`. Receive timestamps come
// from SO_TIMESTAMP (for AF_UNIX the kernel stamps at the receive call).
// send(): MSG_NOSIGNAL (a closed peer is `disconnected`, never SIGPIPE); a full socket buffer
// is `busy`.
// Real-time safety: send/receive/open are non-blocking system calls, no allocation.
#pragma once

#include <cstddef>

#include "pliant/drivers/socketcan/can_transport.hpp"

namespace pliant::drivers::socketcan {

inline constexpr std::size_t kSeqpacketRecordSize = 16;   ///< sizeof(struct can_frame)
inline constexpr std::size_t kMaxSeqpacketAddress = 107;  ///< sun_path minus the terminator

class SeqpacketCanTransport final : public CanTransport {
 public:
  /// A closed transport with no address (open() returns disconnected until adopt()).
  SeqpacketCanTransport() noexcept = default;
  ~SeqpacketCanTransport() override { close(); }

  /// A transport that connects to the listener at `address` on open(). invalid_argument when
  /// the address is empty, too long, or "@" alone (the transport then has no address).
  hal::HalStatus set_address(const char* address) noexcept;
  /// Takes ownership of a connected AF_UNIX SOCK_SEQPACKET descriptor (closing any previous
  /// one): made non-blocking and close-on-exec, SO_TIMESTAMP on. io_error when fd is not usable.
  hal::HalStatus adopt(int fd) noexcept;
  /// Connects a and b through socketpair(AF_UNIX, SOCK_SEQPACKET). io_error if that fails.
  static hal::HalStatus make_pair(SeqpacketCanTransport& a, SeqpacketCanTransport& b) noexcept;

  hal::HalStatus open() noexcept override;
  void close() noexcept override;
  bool is_open() const noexcept override { return fd_ >= 0; }
  CanIo send(const CanFrame& frame) noexcept override;
  CanIo receive(CanFrame& frame, CanRxInfo& info) noexcept override;

  /// Sends `size` arbitrary bytes as one record (tests and emulators: malformed records).
  CanIo send_record(const void* bytes, std::size_t size) noexcept;

 private:
  int fd_ = -1;
  char address_[kMaxSeqpacketAddress + 1] = {};
};

/// The accepting end for SeqpacketCanTransport clients (emulators, HIL rigs).
class SeqpacketCanListener {
 public:
  SeqpacketCanListener() noexcept = default;
  ~SeqpacketCanListener() { close(); }
  SeqpacketCanListener(const SeqpacketCanListener&) = delete;
  SeqpacketCanListener& operator=(const SeqpacketCanListener&) = delete;

  /// Binds and listens at `address` (see SeqpacketCanTransport). A filesystem path that
  /// exists is not replaced: io_error (EADDRINUSE). invalid_argument for a bad address.
  hal::HalStatus listen(const char* address) noexcept;
  /// Non-blocking accept: ok (the connection is adopted by `out`), no_data (no client is
  /// waiting), io_error.
  hal::HalStatus accept(SeqpacketCanTransport& out) noexcept;
  void close() noexcept;
  bool is_open() const noexcept { return fd_ >= 0; }
  int last_errno() const noexcept { return last_errno_; }

 private:
  int fd_ = -1;
  int last_errno_ = 0;
  char path_[kMaxSeqpacketAddress + 1] = {};  ///< filesystem path to unlink on close ("" if abstract)
};

}  // namespace pliant::drivers::socketcan
