// Serial port in raw mode (termios). Reads are non-blocking behind poll(), so a silent line never
// blocks the reader past its timeout.
#include <fcntl.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "fd_io.hpp"
#include "pliant/host/telemetry/transports.hpp"

namespace pliant::host::telemetry {
namespace {

const std::vector<std::pair<int, speed_t>>& speeds() {
  static const std::vector<std::pair<int, speed_t>> table = {
      {1200, B1200},       {2400, B2400},       {4800, B4800},       {9600, B9600},       {19200, B19200},
      {38400, B38400},     {57600, B57600},     {115200, B115200},   {230400, B230400},   {460800, B460800},
      {500000, B500000},   {576000, B576000},   {921600, B921600},   {1000000, B1000000}, {1152000, B1152000},
      {1500000, B1500000}, {2000000, B2000000}, {2500000, B2500000}, {3000000, B3000000}, {3500000, B3500000},
      {4000000, B4000000},
  };
  return table;
}

std::string rate_list() {
  std::string text;
  for (const auto& [rate, code] : speeds()) text += (text.empty() ? "" : ", ") + std::to_string(rate);
  return text;
}

}  // namespace

const std::vector<int>& supported_baud_rates() {
  static const std::vector<int> rates = [] {
    std::vector<int> out;
    for (const auto& [rate, code] : speeds()) out.push_back(rate);
    return out;
  }();
  return rates;
}

struct SerialSource::State {
  int fd = -1;
  std::string device;
  int baud = 0;
  termios original{};
  bool restore = false;
};

SerialSource::SerialSource(const std::string& device, int baud) : state_(std::make_unique<State>()) {
  speed_t speed = B0;
  for (const auto& [rate, code] : speeds()) {
    if (rate == baud) speed = code;
  }
  if (speed == B0) {
    throw std::invalid_argument("unsupported baud rate " + std::to_string(baud) + " (supported: " + rate_list() + ")");
  }
  state_->device = device;
  state_->baud = baud;
  const int fd = ::open(device.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) throw std::runtime_error(device + ": cannot open: " + detail::error_text(errno));
  state_->fd = fd;
  // Closes the port (settings restored) and throws; `error` 0 adds no system message.
  const auto fail = [&](const std::string& what, int error) {
    if (state_->restore) ::tcsetattr(fd, TCSANOW, &state_->original);
    detail::close_quietly(fd);
    state_->fd = -1;
    throw std::runtime_error(device + ": " + what + (error != 0 ? ": " + detail::error_text(error) : ""));
  };
  if (!::isatty(fd)) fail("not a serial port (no terminal attributes)", 0);
  if (::tcgetattr(fd, &state_->original) != 0) fail("cannot read the port settings", errno);
  termios raw = state_->original;
  ::cfmakeraw(&raw);  // no echo, no line editing, no signals, no CR/NL or parity translation
  raw.c_iflag &= ~static_cast<tcflag_t>(IXON | IXOFF | IXANY | INPCK | ISTRIP);
  raw.c_iflag |= IGNBRK;
  raw.c_cflag &= ~static_cast<tcflag_t>(CSIZE | PARENB | CSTOPB | CRTSCTS | HUPCL);
  raw.c_cflag |= static_cast<tcflag_t>(CS8 | CREAD | CLOCAL);
  raw.c_cc[VMIN] = 1;
  raw.c_cc[VTIME] = 0;
  if (::cfsetispeed(&raw, speed) != 0 || ::cfsetospeed(&raw, speed) != 0) fail("cannot set the baud rate", errno);
  if (::tcsetattr(fd, TCSANOW, &raw) != 0) fail("cannot configure the port", errno);
  state_->restore = true;
  // tcsetattr succeeds when any one setting took: read back what matters.
  termios check{};
  if (::tcgetattr(fd, &check) != 0) fail("cannot read the port settings", errno);
  if (::cfgetispeed(&check) != speed || (check.c_lflag & ICANON) != 0 || (check.c_cflag & CSIZE) != CS8) {
    fail("the port refused raw mode at " + std::to_string(baud) + " baud", 0);
  }
  ::tcflush(fd, TCIFLUSH);  // bytes queued before now are the tail of some frame
}

SerialSource::~SerialSource() {
  if (state_ == nullptr || state_->fd < 0) return;
  if (state_->restore) ::tcsetattr(state_->fd, TCSANOW, &state_->original);
  detail::close_quietly(state_->fd);
}

ReadResult SerialSource::read(std::uint8_t* buffer, std::size_t capacity, int timeout_ms) {
  const detail::Ready ready = detail::wait_readable(state_->fd, timeout_ms, state_->device);
  if (ready == detail::Ready::timeout) return {ReadStatus::idle, 0};
  if (ready == detail::Ready::hangup) return {ReadStatus::hangup, 0};
  const ssize_t n = ::read(state_->fd, buffer, capacity);
  if (n > 0) return {ReadStatus::data, static_cast<std::size_t>(n)};
  if (n == 0) return {ReadStatus::hangup, 0};
  if (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR) return {ReadStatus::idle, 0};
  if (errno == EIO || errno == ENXIO || errno == ENODEV) return {ReadStatus::hangup, 0};
  throw std::runtime_error(state_->device + ": read failed: " + detail::error_text(errno));
}

std::string SerialSource::describe() const { return state_->device + " at " + std::to_string(state_->baud) + " baud"; }

}  // namespace pliant::host::telemetry
