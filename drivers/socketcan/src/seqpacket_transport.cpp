#include "pliant/drivers/socketcan/seqpacket_transport.hpp"

#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <cerrno>
#include <cstddef>
#include <cstring>

#include "socket_io.hpp"

namespace pliant::drivers::socketcan {

namespace {

static_assert(kMaxSeqpacketAddress + 1 == sizeof(sockaddr_un{}.sun_path), "sun_path size");

/// sockaddr_un for "@name" (abstract) or a path; false for a bad address.
bool make_address(const char* address, sockaddr_un& addr, socklen_t& len) noexcept {
  if (address == nullptr) return false;
  const std::size_t n = ::strnlen(address, kMaxSeqpacketAddress + 1);
  if (n == 0 || n > kMaxSeqpacketAddress) return false;
  addr = sockaddr_un{};
  addr.sun_family = AF_UNIX;
  if (address[0] == '@') {
    if (n == 1) return false;
    // Abstract namespace: a leading NUL, and the name's bytes without a terminator.
    std::memcpy(addr.sun_path + 1, address + 1, n - 1);
    len = static_cast<socklen_t>(offsetof(sockaddr_un, sun_path) + n);
  } else {
    std::memcpy(addr.sun_path, address, n);
    len = static_cast<socklen_t>(offsetof(sockaddr_un, sun_path) + n + 1);
  }
  return true;
}

bool peer_gone(int e) noexcept { return e == EPIPE || e == ECONNRESET || e == ENOTCONN || e == ECONNREFUSED; }

}  // namespace

hal::HalStatus SeqpacketCanTransport::set_address(const char* address) noexcept {
  sockaddr_un addr;
  socklen_t len = 0;
  if (!make_address(address, addr, len)) {
    address_[0] = '\0';
    return hal::HalStatus::invalid_argument;
  }
  const std::size_t n = ::strnlen(address, kMaxSeqpacketAddress);
  std::memcpy(address_, address, n);
  address_[n] = '\0';
  return hal::HalStatus::ok;
}

hal::HalStatus SeqpacketCanTransport::adopt(int fd) noexcept {
  close();
  if (fd < 0) return hal::HalStatus::io_error;
  if (!detail::make_nonblocking(fd) || !detail::enable_timestamps(fd)) {
    set_errno(errno);
    ::close(fd);
    return hal::HalStatus::io_error;
  }
  fd_ = fd;
  return hal::HalStatus::ok;
}

hal::HalStatus SeqpacketCanTransport::make_pair(SeqpacketCanTransport& a, SeqpacketCanTransport& b) noexcept {
  int fds[2] = {-1, -1};
  if (::socketpair(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0, fds) < 0) {
    a.set_errno(errno);
    return hal::HalStatus::io_error;
  }
  const hal::HalStatus sa = a.adopt(fds[0]);
  if (sa != hal::HalStatus::ok) {
    ::close(fds[1]);
    return sa;
  }
  const hal::HalStatus sb = b.adopt(fds[1]);
  if (sb != hal::HalStatus::ok) a.close();
  return sb;
}

hal::HalStatus SeqpacketCanTransport::open() noexcept {
  if (fd_ >= 0) return hal::HalStatus::ok;
  sockaddr_un addr;
  socklen_t len = 0;
  if (!make_address(address_, addr, len)) return hal::HalStatus::disconnected;  // an adopted end cannot reconnect
  const int fd = ::socket(AF_UNIX, SOCK_SEQPACKET | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (fd < 0) {
    set_errno(errno);
    return hal::HalStatus::io_error;
  }
  // A non-blocking AF_UNIX connect completes at once or fails at once (no listener, full backlog).
  if (::connect(fd, reinterpret_cast<const sockaddr*>(&addr), len) < 0) {
    const int e = errno;
    set_errno(e);
    ::close(fd);
    const bool absent = e == ECONNREFUSED || e == ENOENT || e == EAGAIN || e == EWOULDBLOCK || e == EINPROGRESS;
    return absent ? hal::HalStatus::disconnected : hal::HalStatus::io_error;
  }
  if (!detail::enable_timestamps(fd)) {
    set_errno(errno);
    ::close(fd);
    return hal::HalStatus::io_error;
  }
  fd_ = fd;
  return hal::HalStatus::ok;
}

void SeqpacketCanTransport::close() noexcept {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
}

CanIo SeqpacketCanTransport::send_record(const void* bytes, std::size_t size) noexcept {
  if (fd_ < 0) return CanIo::disconnected;
  const ssize_t n = ::send(fd_, bytes, size, MSG_NOSIGNAL | MSG_DONTWAIT);
  if (n == static_cast<ssize_t>(size)) return CanIo::ok;
  if (n >= 0) return CanIo::io_error;
  set_errno(errno);
  if (errno == EAGAIN || errno == EWOULDBLOCK || errno == ENOBUFS || errno == EINTR) return CanIo::busy;
  if (peer_gone(errno)) {
    close();
    return CanIo::disconnected;
  }
  return CanIo::io_error;
}

CanIo SeqpacketCanTransport::send(const CanFrame& frame) noexcept {
  unsigned char record[kSeqpacketRecordSize];
  detail::record_from_frame(frame, record);
  return send_record(record, sizeof record);
}

CanIo SeqpacketCanTransport::receive(CanFrame& frame, CanRxInfo& info) noexcept {
  if (fd_ < 0) return CanIo::disconnected;
  // One byte more than a record, so that an oversized record shows as truncated or too long.
  alignas(8) unsigned char record[kSeqpacketRecordSize + 1];
  const detail::Record r = detail::receive_record(fd_, record, sizeof record);
  if (r.bytes < 0) {
    if (r.err == EAGAIN || r.err == EWOULDBLOCK || r.err == EINTR) return CanIo::empty;
    set_errno(r.err);
    if (peer_gone(r.err)) {
      close();
      return CanIo::disconnected;
    }
    return CanIo::io_error;
  }
  if (r.bytes == 0) {
    // End of stream: the peer closed. (A zero-length record would read the same; no CAN
    // frame is zero bytes, so a peer that sends one is treated as gone as well.)
    close();
    return CanIo::disconnected;
  }
  if (r.truncated || r.bytes != static_cast<ssize_t>(kSeqpacketRecordSize)) return CanIo::malformed;
  if (!detail::frame_from_record(record, frame)) return CanIo::malformed;
  info.realtime_ns = r.realtime_ns;
  return CanIo::ok;
}

hal::HalStatus SeqpacketCanListener::listen(const char* address) noexcept {
  close();
  sockaddr_un addr;
  socklen_t len = 0;
  if (!make_address(address, addr, len)) return hal::HalStatus::invalid_argument;
  const int fd = ::socket(AF_UNIX, SOCK_SEQPACKET | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (fd < 0) {
    last_errno_ = errno;
    return hal::HalStatus::io_error;
  }
  if (::bind(fd, reinterpret_cast<const sockaddr*>(&addr), len) < 0 || ::listen(fd, 4) < 0) {
    last_errno_ = errno;
    ::close(fd);
    return hal::HalStatus::io_error;
  }
  fd_ = fd;
  path_[0] = '\0';
  if (address[0] != '@') {
    const std::size_t n = ::strnlen(address, kMaxSeqpacketAddress);
    std::memcpy(path_, address, n);
    path_[n] = '\0';
  }
  return hal::HalStatus::ok;
}

hal::HalStatus SeqpacketCanListener::accept(SeqpacketCanTransport& out) noexcept {
  if (fd_ < 0) return hal::HalStatus::io_error;
  const int fd = ::accept4(fd_, nullptr, nullptr, SOCK_NONBLOCK | SOCK_CLOEXEC);
  if (fd < 0) {
    last_errno_ = errno;
    return errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR ? hal::HalStatus::no_data
                                                                     : hal::HalStatus::io_error;
  }
  return out.adopt(fd);
}

void SeqpacketCanListener::close() noexcept {
  if (fd_ >= 0) {
    ::close(fd_);
    if (path_[0] != '\0') ::unlink(path_);
  }
  fd_ = -1;
  path_[0] = '\0';
}

}  // namespace pliant::drivers::socketcan
