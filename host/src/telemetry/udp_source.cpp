// UDP socket bound to a numeric address; datagram payloads are read as one byte stream.
#include <arpa/inet.h>
#include <netdb.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <stdexcept>
#include <string>

#include "fd_io.hpp"
#include "pliant/host/telemetry/transports.hpp"

namespace pliant::host::telemetry {

struct UdpSource::State {
  int fd = -1;
  std::string address;
  int port = 0;
};

namespace {

std::string endpoint(const std::string& address, int port) {
  const bool v6 = address.find(':') != std::string::npos;
  return "udp " + (v6 ? "[" + address + "]" : address) + ":" + std::to_string(port);
}

int bound_port(int fd) {
  sockaddr_storage local{};
  socklen_t size = sizeof local;
  if (::getsockname(fd, reinterpret_cast<sockaddr*>(&local), &size) != 0) return -1;
  if (local.ss_family == AF_INET) return ntohs(reinterpret_cast<const sockaddr_in*>(&local)->sin_port);
  if (local.ss_family == AF_INET6) return ntohs(reinterpret_cast<const sockaddr_in6*>(&local)->sin6_port);
  return -1;
}

}  // namespace

UdpSource::UdpSource(const std::string& bind_address, int port) : state_(std::make_unique<State>()) {
  if (port < 0 || port > 65535) throw std::invalid_argument("UDP port " + std::to_string(port) + " is not in 0..65535");
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_DGRAM;
  hints.ai_flags = AI_NUMERICHOST | AI_NUMERICSERV | AI_PASSIVE;
  addrinfo* found = nullptr;
  const std::string service = std::to_string(port);
  if (::getaddrinfo(bind_address.c_str(), service.c_str(), &hints, &found) != 0 || found == nullptr) {
    throw std::invalid_argument("'" + bind_address + "' is not a numeric IPv4 or IPv6 address");
  }
  state_->address = bind_address;
  const std::string what = endpoint(bind_address, port);
  const int fd = ::socket(found->ai_family, found->ai_socktype | SOCK_CLOEXEC, found->ai_protocol);
  if (fd < 0) {
    const int error = errno;
    ::freeaddrinfo(found);
    throw std::runtime_error(what + ": cannot create a socket: " + detail::error_text(error));
  }
  // A deeper receive queue rides out bursts (particle chunks) while the host is busy writing.
  const int queue_bytes = 1 << 20;
  ::setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &queue_bytes, sizeof queue_bytes);
  const int bound = ::bind(fd, found->ai_addr, found->ai_addrlen);
  const int error = errno;
  ::freeaddrinfo(found);
  if (bound != 0) {
    detail::close_quietly(fd);
    throw std::runtime_error(what + ": cannot bind: " + detail::error_text(error));
  }
  state_->fd = fd;
  state_->port = bound_port(fd);
  if (state_->port < 0) {
    detail::close_quietly(fd);
    state_->fd = -1;
    throw std::runtime_error(what + ": cannot read the bound port");
  }
}

UdpSource::~UdpSource() {
  if (state_ != nullptr) detail::close_quietly(state_->fd);
}

ReadResult UdpSource::read(std::uint8_t* buffer, std::size_t capacity, int timeout_ms) {
  const detail::Ready ready = detail::wait_readable(state_->fd, timeout_ms, describe());
  if (ready != detail::Ready::readable) return {ReadStatus::idle, 0};  // a socket does not hang up
  const ssize_t n = ::recv(state_->fd, buffer, capacity, MSG_DONTWAIT);
  if (n > 0) return {ReadStatus::data, static_cast<std::size_t>(n)};
  if (n == 0) return {ReadStatus::idle, 0};  // an empty datagram
  if (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR || errno == ECONNREFUSED) {
    return {ReadStatus::idle, 0};
  }
  throw std::runtime_error(describe() + ": receive failed: " + detail::error_text(errno));
}

std::string UdpSource::describe() const { return endpoint(state_->address, state_->port); }

int UdpSource::port() const { return state_->port; }

}  // namespace pliant::host::telemetry
