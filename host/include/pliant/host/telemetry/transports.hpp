// The three telemetry transports. Each opens its device in the constructor (so that a bad path
// or port fails before any reading starts), closes it in the destructor, and throws
// std::runtime_error with one line naming the device and the cause when it cannot.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "pliant/host/telemetry/byte_source.hpp"

namespace pliant::host::telemetry {

/// Baud rates a SerialSource accepts (the POSIX/Linux standard rates, 1200 .. 4000000).
const std::vector<int>& supported_baud_rates();

/// A serial port (UART, USB CDC-ACM, pseudo-terminal) in raw mode: 8 data bits, no parity, one
/// stop bit, no flow control, no echo, no line editing, no character translation, receiver on,
/// modem lines ignored. Input already queued when the port opens is discarded (it would be the
/// tail of a frame). The original terminal settings are restored on destruction.
class SerialSource final : public ByteSource {
 public:
  /// Throws std::invalid_argument when `baud` is not in supported_baud_rates(), and
  /// std::runtime_error when the device cannot be opened or configured.
  SerialSource(const std::string& device, int baud = 115200);
  ~SerialSource() override;
  ReadResult read(std::uint8_t* buffer, std::size_t capacity, int timeout_ms) override;
  std::string describe() const override;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

/// A UDP socket bound to `bind_address` (a numeric IPv4 or IPv6 address; "127.0.0.1" only
/// accepts datagrams from this machine, "0.0.0.0" from anywhere) and `port` (0: the system
/// picks one, see port()). Datagram payloads are concatenated into one byte stream, so a frame
/// may span datagrams and a datagram may hold several frames.
class UdpSource final : public ByteSource {
 public:
  /// Throws std::invalid_argument for an address that is not numeric or a port above 65535,
  /// std::runtime_error when the socket cannot be bound (port in use, no such address, ...).
  UdpSource(const std::string& bind_address, int port);
  ~UdpSource() override;
  ReadResult read(std::uint8_t* buffer, std::size_t capacity, int timeout_ms) override;
  std::string describe() const override;
  /// The bound port (the one the system picked when constructed with 0).
  int port() const;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

/// A file, a FIFO, or standard input when `path` is "-" (not closed on destruction).
class FileSource final : public ByteSource {
 public:
  /// Throws std::runtime_error when the file cannot be opened or is a directory.
  explicit FileSource(const std::string& path);
  ~FileSource() override;
  ReadResult read(std::uint8_t* buffer, std::size_t capacity, int timeout_ms) override;
  std::string describe() const override;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace pliant::host::telemetry
