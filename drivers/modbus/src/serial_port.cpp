#include "serial_port.hpp"

#include <fcntl.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>

namespace pliant::drivers::modbus::detail {
namespace {

speed_t speed_of(int baud) noexcept {
  switch (baud) {
    case 1200: return B1200;
    case 2400: return B2400;
    case 4800: return B4800;
    case 9600: return B9600;
    case 19200: return B19200;
    case 38400: return B38400;
    case 57600: return B57600;
    case 115200: return B115200;
    case 230400: return B230400;
    default: return B0;
  }
}

}  // namespace

bool serial_baud_supported(int baud) noexcept { return speed_of(baud) != B0; }

int open_serial_port(const char* path, int baud, int& err) noexcept {
  const speed_t speed = speed_of(baud);
  if (speed == B0) {
    err = EINVAL;
    return -1;
  }
  const int fd = ::open(path, O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) {
    err = errno;
    return -1;
  }
  termios tio{};
  if (tcgetattr(fd, &tio) != 0) {
    err = errno;
    ::close(fd);
    return -1;
  }
  cfmakeraw(&tio);
  tio.c_cflag &= ~static_cast<tcflag_t>(CSTOPB | PARENB | CSIZE | CRTSCTS);
  tio.c_cflag |= static_cast<tcflag_t>(CS8 | CLOCAL | CREAD);
  tio.c_iflag &= ~static_cast<tcflag_t>(IXON | IXOFF | IXANY);
  // VMIN = 1 with O_NONBLOCK: an empty port reads -1/EAGAIN, so 0 keeps its meaning of end of
  // file (a hung-up tty). With VMIN = 0 Linux returns 0 for "no data" as well.
  tio.c_cc[VMIN] = 1;
  tio.c_cc[VTIME] = 0;
  if (cfsetispeed(&tio, speed) != 0 || cfsetospeed(&tio, speed) != 0 || tcsetattr(fd, TCSANOW, &tio) != 0) {
    err = errno;
    ::close(fd);
    return -1;
  }
  err = 0;
  return fd;
}

bool write_now(int fd, const std::uint8_t* data, std::size_t size, int& err) noexcept {
  std::size_t done = 0;
  // Bounded: every pass writes at least one byte or returns.
  while (done < size) {
    const ssize_t n = ::write(fd, data + done, size - done);
    if (n > 0) {
      done += static_cast<std::size_t>(n);
      continue;
    }
    if (n < 0 && errno == EINTR) continue;
    err = n < 0 ? errno : EIO;
    return false;
  }
  err = 0;
  return true;
}

}  // namespace pliant::drivers::modbus::detail
