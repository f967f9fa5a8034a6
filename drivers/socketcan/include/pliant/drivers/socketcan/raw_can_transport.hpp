// pliant socketcan driver: the real bus, an AF_CAN raw socket bound to one interface.
//
// open(): socket(PF_CAN, SOCK_RAW | SOCK_NONBLOCK, CAN_RAW), the interface index looked up by
// name (SIOCGIFINDEX), one exact-match filter per wanted ID (mask CAN_EFF_FLAG | CAN_RTR_FLAG |
// CAN_SFF_MASK: the kernel's fast path, and extended or remote frames with the same low bits do
// not pass), the error filter (CAN_RAW_ERR_FILTER = config.error_mask), SO_TIMESTAMP, bind.
// Loopback stays as the kernel sets it (on, own frames not received).
//   unsupported   the kernel has no AF_CAN (EAFNOSUPPORT: containers, many CI machines)
//   disconnected  no interface by that name now (ENODEV): plug the adapter in, or
//                 `ip link add dev vcan0 type vcan`; open() again later
//   invalid_argument  empty name or longer than 15 characters
// receive(): one struct can_frame (CAN_MTU bytes) per call; a different size (CAN FD) is
// malformed. ENETDOWN / ENODEV / ENXIO (interface down or removed) are `disconnected`.
// send(): ENOBUFS / EAGAIN (queue full, e.g. during bus-off or with no other node to ACK)
// are `busy`.
// Bus-off recovery is an interface setting, not a socket call:
//   ip link set can0 type can restart-ms 100
// The kernel then restarts the controller and sends an error frame with kCanErrRestarted.
// Real-time safety: send/receive are one non-blocking system call each, no allocation.
#pragma once

#include <cstdint>

#include "pliant/drivers/socketcan/can_error.hpp"
#include "pliant/drivers/socketcan/can_transport.hpp"

namespace pliant::drivers::socketcan {

struct RawCanConfig {
  char interface_name[16] = "can0";                 ///< NUL-terminated, at most 15 characters
  std::uint32_t error_mask = kDefaultCanErrorMask;  ///< error classes to receive (0: none)
  bool receive_timestamps = true;                   ///< SO_TIMESTAMP on received frames
};

class RawCanTransport final : public CanTransport {
 public:
  explicit RawCanTransport(const RawCanConfig& config) noexcept : config_(config) {}
  ~RawCanTransport() override { close(); }

  hal::HalStatus open() noexcept override;
  void close() noexcept override;
  bool is_open() const noexcept override { return fd_ >= 0; }
  CanIo send(const CanFrame& frame) noexcept override;
  CanIo receive(CanFrame& frame, CanRxInfo& info) noexcept override;

  const RawCanConfig& config() const noexcept { return config_; }

 private:
  RawCanConfig config_;
  int fd_ = -1;
};

}  // namespace pliant::drivers::socketcan
