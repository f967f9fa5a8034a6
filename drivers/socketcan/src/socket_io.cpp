#include "socket_io.hpp"

#include <fcntl.h>
#include <linux/can.h>
#include <sys/socket.h>
#include <sys/time.h>

#include <cerrno>
#include <cstring>

namespace pliant::drivers::socketcan::detail {

// CanFrame mirrors the kernel's layout; make sure they agree.
static_assert(kCanEffFlag == CAN_EFF_FLAG && kCanRtrFlag == CAN_RTR_FLAG && kCanErrFlag == CAN_ERR_FLAG, "flags");
static_assert(kCanSffMask == CAN_SFF_MASK && kCanEffMask == CAN_EFF_MASK, "masks");
static_assert(sizeof(struct can_frame) == 16, "struct can_frame is 16 bytes");
static_assert(CAN_MAX_DLEN == kCanMaxDlc, "dlc");

Record receive_record(int fd, void* buf, std::size_t capacity) noexcept {
  Record r;
  iovec iov{buf, capacity};
  // Room for one struct timeval control message; aligned as cmsghdr requires.
  alignas(cmsghdr) unsigned char control[CMSG_SPACE(sizeof(timeval))];
  msghdr msg{};
  msg.msg_iov = &iov;
  msg.msg_iovlen = 1;
  msg.msg_control = control;
  msg.msg_controllen = sizeof control;
  r.bytes = ::recvmsg(fd, &msg, MSG_DONTWAIT);
  if (r.bytes < 0) {
    r.err = errno;
    return r;
  }
  r.truncated = (msg.msg_flags & MSG_TRUNC) != 0;
  for (cmsghdr* c = CMSG_FIRSTHDR(&msg); c != nullptr; c = CMSG_NXTHDR(&msg, c)) {
    if (c->cmsg_level == SOL_SOCKET && c->cmsg_type == SCM_TIMESTAMP && c->cmsg_len >= CMSG_LEN(sizeof(timeval))) {
      timeval tv{};
      std::memcpy(&tv, CMSG_DATA(c), sizeof tv);
      r.realtime_ns = static_cast<std::int64_t>(tv.tv_sec) * 1000000000 + static_cast<std::int64_t>(tv.tv_usec) * 1000;
    }
  }
  return r;
}

bool frame_from_record(const void* record, CanFrame& out) noexcept {
  struct can_frame k;
  std::memcpy(&k, record, sizeof k);
  if (k.len > CAN_MAX_DLEN) return false;
  CanFrame f;
  f.id = k.can_id;
  f.dlc = k.len;
  std::memcpy(f.data, k.data, k.len);
  out = f;
  return true;
}

void record_from_frame(const CanFrame& frame, void* record) noexcept {
  struct can_frame k;
  std::memset(&k, 0, sizeof k);
  k.can_id = frame.id;
  k.len = frame.dlc > CAN_MAX_DLEN ? static_cast<__u8>(CAN_MAX_DLEN) : frame.dlc;
  std::memcpy(k.data, frame.data, k.len);
  std::memcpy(record, &k, sizeof k);
}

bool make_nonblocking(int fd) noexcept {
  const int fl = ::fcntl(fd, F_GETFL);
  if (fl < 0 || ::fcntl(fd, F_SETFL, fl | O_NONBLOCK) < 0) return false;
  const int fd_flags = ::fcntl(fd, F_GETFD);
  return fd_flags >= 0 && ::fcntl(fd, F_SETFD, fd_flags | FD_CLOEXEC) >= 0;
}

bool enable_timestamps(int fd) noexcept {
  const int on = 1;
  return ::setsockopt(fd, SOL_SOCKET, SO_TIMESTAMP, &on, sizeof on) == 0;
}

}  // namespace pliant::drivers::socketcan::detail
