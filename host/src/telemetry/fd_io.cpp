#include "fd_io.hpp"

#include <poll.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

namespace pliant::host::telemetry::detail {

std::string error_text(int error) { return std::strerror(error); }

void close_quietly(int fd) {
  if (fd < 0) return;
  const int saved = errno;
  ::close(fd);
  errno = saved;
}

Ready wait_readable(int fd, int timeout_ms, const std::string& what) {
  pollfd entry{};
  entry.fd = fd;
  entry.events = POLLIN;
  const int ready = ::poll(&entry, 1, timeout_ms < 0 ? 0 : timeout_ms);
  if (ready < 0) {
    if (errno == EINTR) return Ready::timeout;
    throw std::runtime_error(what + ": cannot wait for data: " + error_text(errno));
  }
  if (ready == 0) return Ready::timeout;
  if ((entry.revents & POLLIN) != 0) return Ready::readable;
  if ((entry.revents & (POLLHUP | POLLERR)) != 0) return Ready::hangup;
  if ((entry.revents & POLLNVAL) != 0) throw std::runtime_error(what + ": not open");
  return Ready::timeout;
}

}  // namespace pliant::host::telemetry::detail
