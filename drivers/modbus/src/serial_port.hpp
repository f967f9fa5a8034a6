// Private to the modbus driver: a raw, non-blocking serial port for the FT 300 stream mode.
// open_serial_port() sets 8N1 at `baud`, raw input and output (no echo, no line editing, no
// CR/LF translation, no flow control), VMIN = 1, VTIME = 0 and O_NONBLOCK, so reads never wait:
// no data reads -1 with EAGAIN, end of file (hang-up) reads 0.
// Works on real ttys and on pseudo-terminals (the tests use a pty).
#pragma once

#include <cstddef>
#include <cstdint>

namespace pliant::drivers::modbus::detail {

/// True when `baud` is one of the rates this helper can set (1200 .. 230400).
bool serial_baud_supported(int baud) noexcept;

/// Opens and configures `path`. Returns the fd, or -1 with `err` set to the errno.
int open_serial_port(const char* path, int baud, int& err) noexcept;

/// Writes all `size` bytes to a non-blocking fd without waiting: true when every byte went out
/// at once; false with `err` set otherwise (EAGAIN when the output buffer was full).
bool write_now(int fd, const std::uint8_t* data, std::size_t size, int& err) noexcept;

}  // namespace pliant::drivers::modbus::detail
