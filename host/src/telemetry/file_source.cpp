// A file, FIFO or standard input, read through poll() so that a quiet pipe honours the timeout.
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <stdexcept>
#include <string>

#include "fd_io.hpp"
#include "pliant/host/telemetry/transports.hpp"

namespace pliant::host::telemetry {

struct FileSource::State {
  int fd = -1;
  bool owned = false;
  std::string label;
};

FileSource::FileSource(const std::string& path) : state_(std::make_unique<State>()) {
  if (path == "-") {
    state_->fd = STDIN_FILENO;
    state_->label = "standard input";
    return;
  }
  state_->label = path;
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw std::runtime_error(path + ": cannot open: " + detail::error_text(errno));
  struct stat info {};
  if (::fstat(fd, &info) != 0 || S_ISDIR(info.st_mode)) {
    detail::close_quietly(fd);
    throw std::runtime_error(path + ": not a file");
  }
  state_->fd = fd;
  state_->owned = true;
}

FileSource::~FileSource() {
  if (state_ != nullptr && state_->owned) detail::close_quietly(state_->fd);
}

ReadResult FileSource::read(std::uint8_t* buffer, std::size_t capacity, int timeout_ms) {
  const detail::Ready ready = detail::wait_readable(state_->fd, timeout_ms, state_->label);
  if (ready == detail::Ready::timeout) return {ReadStatus::idle, 0};
  if (ready == detail::Ready::hangup) return {ReadStatus::end, 0};  // the writer closed the pipe
  const ssize_t n = ::read(state_->fd, buffer, capacity);
  if (n > 0) return {ReadStatus::data, static_cast<std::size_t>(n)};
  if (n == 0) return {ReadStatus::end, 0};
  if (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR) return {ReadStatus::idle, 0};
  throw std::runtime_error(state_->label + ": read failed: " + detail::error_text(errno));
}

std::string FileSource::describe() const { return state_->label; }

}  // namespace pliant::host::telemetry
