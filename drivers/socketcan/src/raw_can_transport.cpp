#include "pliant/drivers/socketcan/raw_can_transport.hpp"

#include <linux/can.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "socket_io.hpp"

namespace pliant::drivers::socketcan {

namespace {

bool link_gone(int e) noexcept { return e == ENETDOWN || e == ENODEV || e == ENXIO; }

}  // namespace

hal::HalStatus RawCanTransport::open() noexcept {
  if (fd_ >= 0) return hal::HalStatus::ok;
  const std::size_t name_len = ::strnlen(config_.interface_name, sizeof config_.interface_name);
  if (name_len == 0 || name_len >= sizeof config_.interface_name || name_len >= IFNAMSIZ) {
    return hal::HalStatus::invalid_argument;
  }
  const int fd = ::socket(PF_CAN, SOCK_RAW | SOCK_NONBLOCK | SOCK_CLOEXEC, CAN_RAW);
  if (fd < 0) {
    set_errno(errno);
    return errno == EAFNOSUPPORT || errno == EPROTONOSUPPORT ? hal::HalStatus::unsupported : hal::HalStatus::io_error;
  }
  auto fail = [&](hal::HalStatus status) {
    set_errno(errno);
    ::close(fd);
    return status;
  };
  ifreq ifr{};
  std::memcpy(ifr.ifr_name, config_.interface_name, name_len);
  if (::ioctl(fd, SIOCGIFINDEX, &ifr) < 0) {
    return fail(errno == ENODEV ? hal::HalStatus::disconnected : hal::HalStatus::io_error);
  }
  // One exact-match filter per ID: the kernel's fast path for standard IDs.
  can_filter filters[kMaxCanFilterIds];
  const std::size_t n = filter_count();
  for (std::size_t i = 0; i < n; ++i) {
    filters[i].can_id = filter_ids()[i];
    filters[i].can_mask = CAN_EFF_FLAG | CAN_RTR_FLAG | CAN_SFF_MASK;
  }
  if (n > 0 &&
      ::setsockopt(fd, SOL_CAN_RAW, CAN_RAW_FILTER, filters, static_cast<socklen_t>(n * sizeof(can_filter))) < 0) {
    return fail(hal::HalStatus::io_error);
  }
  const can_err_mask_t err_mask = config_.error_mask & CAN_ERR_MASK;
  if (::setsockopt(fd, SOL_CAN_RAW, CAN_RAW_ERR_FILTER, &err_mask, sizeof err_mask) < 0) {
    return fail(hal::HalStatus::io_error);
  }
  if (config_.receive_timestamps && !detail::enable_timestamps(fd)) return fail(hal::HalStatus::io_error);
  sockaddr_can addr{};
  addr.can_family = AF_CAN;
  addr.can_ifindex = ifr.ifr_ifindex;
  if (::bind(fd, reinterpret_cast<const sockaddr*>(&addr), sizeof addr) < 0) {
    return fail(link_gone(errno) ? hal::HalStatus::disconnected : hal::HalStatus::io_error);
  }
  fd_ = fd;
  return hal::HalStatus::ok;
}

void RawCanTransport::close() noexcept {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
}

CanIo RawCanTransport::send(const CanFrame& frame) noexcept {
  if (fd_ < 0) return CanIo::disconnected;
  unsigned char record[sizeof(struct can_frame)];
  detail::record_from_frame(frame, record);
  const ssize_t n = ::write(fd_, record, sizeof record);
  if (n == static_cast<ssize_t>(sizeof record)) return CanIo::ok;
  if (n >= 0) return CanIo::io_error;  // a raw CAN socket writes whole frames or nothing
  set_errno(errno);
  if (errno == ENOBUFS || errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR) return CanIo::busy;
  if (link_gone(errno)) {
    close();
    return CanIo::disconnected;
  }
  return CanIo::io_error;
}

CanIo RawCanTransport::receive(CanFrame& frame, CanRxInfo& info) noexcept {
  if (fd_ < 0) return CanIo::disconnected;
  alignas(struct can_frame) unsigned char record[sizeof(struct can_frame)];
  const detail::Record r = detail::receive_record(fd_, record, sizeof record);
  if (r.bytes < 0) {
    if (r.err == EAGAIN || r.err == EWOULDBLOCK || r.err == EINTR) return CanIo::empty;
    set_errno(r.err);
    if (link_gone(r.err)) {
      close();
      return CanIo::disconnected;
    }
    return CanIo::io_error;
  }
  if (r.truncated || r.bytes != static_cast<ssize_t>(sizeof record)) return CanIo::malformed;
  if (!detail::frame_from_record(record, frame)) return CanIo::malformed;
  info.realtime_ns = r.realtime_ns;
  return CanIo::ok;
}

}  // namespace pliant::drivers::socketcan
