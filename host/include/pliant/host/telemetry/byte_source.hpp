// Where telemetry bytes come from: a serial port, a UDP socket or a file (transports.hpp).
// Host code: implementations allocate, and throw std::runtime_error (one line naming the device
// and the cause) when the device cannot be opened or read.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace pliant::host::telemetry {

enum class ReadStatus {
  data,    ///< `bytes` > 0 bytes were read
  idle,    ///< nothing arrived within the timeout (or a signal interrupted the wait)
  end,     ///< end of file: no more bytes will come
  hangup,  ///< the device went away (serial port unplugged, pseudo-terminal closed)
};

struct ReadResult {
  ReadStatus status = ReadStatus::idle;
  std::size_t bytes = 0;
};

/// A byte stream with a bounded wait. Not copyable; one reader at a time.
class ByteSource {
 public:
  virtual ~ByteSource() = default;
  ByteSource() = default;
  ByteSource(const ByteSource&) = delete;
  ByteSource& operator=(const ByteSource&) = delete;

  /// Reads at most `capacity` bytes into `buffer`, waiting at most `timeout_ms` (>= 0)
  /// milliseconds for the first one. A UDP source returns one datagram per call (truncated to
  /// `capacity`). Throws std::runtime_error on an I/O error.
  virtual ReadResult read(std::uint8_t* buffer, std::size_t capacity, int timeout_ms) = 0;

  /// What is being read, for messages: "/dev/ttyACM0 at 115200 baud", "udp 127.0.0.1:5600",
  /// "capture.bin", "standard input".
  virtual std::string describe() const = 0;
};

}  // namespace pliant::host::telemetry
