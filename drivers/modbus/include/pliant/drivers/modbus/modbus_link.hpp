// pliant modbus driver: one Modbus client link (libmodbus 3.1.x), RTU over a serial device or
// TCP, with bounded transactions, error mapping and automatic reconnection.
//
// Bounds (what "bounded" means for the devices built on this link):
//   - A transaction (one request, one response) waits at most response_timeout_s for the whole
//     response: the byte timeout is switched off, so libmodbus's select() keeps counting down the
//     same budget across bytes (Linux select() updates the remaining time). Sending the request
//     is a write of at most 260 bytes to a serial port or a TCP socket.
//   - Reconnecting (TCP connect, or reopening the serial device) is tried at most once per
//     reconnect_interval_s (on the injected clock) and a TCP connect waits at most
//     response_timeout_s (libmodbus 3.1.6 connects non-blocking with that timeout).
//   - libmodbus's own error recovery (which sleeps and reconnects inside a call) stays off.
//   So a call here returns within about (transactions it makes) x response_timeout_s. It never
//   waits forever; it is not "non-blocking" in the strict sense: keep response_timeout_s small
//   (default 20 ms) and call it from a thread whose period allows for it.
//
// Error mapping (errno after a failed libmodbus call, see modbus_errno_status()):
//   ETIMEDOUT, EMBXGTAR (gateway target did not answer)              -> timeout
//   ECONNRESET, ECONNREFUSED, EPIPE, ENOTCONN, EBADF, EIO, ENXIO, ENODEV,
//   ENOENT, EHOSTUNREACH, ENETUNREACH, ENETDOWN, ECONNABORTED, EACCES -> disconnected
//   EMBXILFUN (exception "illegal function")                          -> unsupported
//   EMBBADCRC, EMBBADDATA, EMBBADEXC, EMBUNKEXC, EMBMDATA, EMBBADSLAVE,
//   other Modbus exceptions, anything else                            -> io_error
// After disconnected the link is closed; the next transaction after reconnect_interval_s tries
// to reconnect (counted) and goes on with the request when that succeeds. After a timeout or a
// bad response the receive buffer is flushed before the next request, so a late answer is not
// taken for the next one (TCP also checks transaction IDs; RTU cannot, see docs/drivers/modbus.md).
//
// Allocation: open() allocates (libmodbus context); transactions do not allocate (tested with
// the counting allocator). Reconnects make no allocation in this code, and libmodbus's plain TCP
// and RTU connects use no heap (no getaddrinfo); the tests do not count that path.
// Thread safety: one thread drives a link. Not copyable.
#pragma once

#include <cstdint>
#include <string>

#include "pliant/hal/clock.hpp"
#include "pliant/hal/status.hpp"

struct _modbus;  // libmodbus's modbus_t (typedef struct _modbus modbus_t in modbus.h)

namespace pliant::drivers::modbus {

enum class ModbusTransport : std::uint8_t { rtu, tcp };

struct ModbusLinkConfig {
  ModbusTransport transport = ModbusTransport::rtu;
  // RTU
  std::string device = "/dev/ttyUSB0";  ///< serial device
  int baud = 115200;                    ///< > 0
  char parity = 'N';                    ///< 'N', 'E' or 'O'
  int data_bits = 8;                    ///< 5..8
  int stop_bits = 1;                    ///< 1 or 2
  // TCP
  std::string host = "127.0.0.1";  ///< IPv4 address (dotted quad; no name lookup)
  int port = 502;                  ///< 1..65535
  // Both
  int slave_id = 9;                   ///< 0..247 (the unit identifier over TCP)
  double response_timeout_s = 0.02;   ///< whole-response budget per transaction, (0, 10] s
  double reconnect_interval_s = 0.1;  ///< minimum time between reconnection attempts, >= 0
};

/// invalid_argument when a field breaks its documented range, else ok.
hal::HalStatus validate(const ModbusLinkConfig& config) noexcept;

/// Which register table a read addresses.
enum class RegisterTable : std::uint8_t {
  holding,  ///< FC03 Read Holding Registers
  input,    ///< FC04 Read Input Registers
};

/// The HalStatus for errno `err` after a failed libmodbus call (table above).
hal::HalStatus modbus_errno_status(int err) noexcept;

/// Monotonic link counters (reset by open()).
struct ModbusLinkCounters {
  std::uint64_t transactions = 0;        ///< requests sent (read or write)
  std::uint64_t failures = 0;            ///< transactions that failed, any cause
  std::uint64_t timeouts = 0;            ///< ... with timeout
  std::uint64_t bad_responses = 0;       ///< ... with a CRC error or malformed/mismatched answer
  std::uint64_t exceptions = 0;          ///< ... with a Modbus exception reply (any code)
  std::uint64_t disconnects = 0;         ///< transitions connected -> disconnected
  std::uint64_t reconnect_attempts = 0;  ///< reconnection tries (each at most one connect)
  std::uint64_t reconnects = 0;          ///< reconnection tries that succeeded
  std::uint64_t flushes = 0;             ///< receive-buffer flushes after a timeout or bad response
  int last_errno = 0;                    ///< errno of the last failure (0 before any)
};

class ModbusLink {
 public:
  explicit ModbusLink(const hal::Clock& clock) noexcept : clock_(clock) {}
  ~ModbusLink();
  ModbusLink(const ModbusLink&) = delete;
  ModbusLink& operator=(const ModbusLink&) = delete;

  /// Validates `config`, creates the libmodbus context and connects. invalid_argument for a bad
  /// configuration, capacity_exceeded when the context cannot be created, else the mapped
  /// status of a failed connect (the link is then closed again). Any previous link is closed.
  hal::HalStatus open(const ModbusLinkConfig& config);
  /// Disconnects and frees the context. Idempotent.
  void close() noexcept;
  bool is_open() const noexcept { return ctx_ != nullptr; }
  /// True while the link believes it is connected (false after a disconnection until a
  /// reconnection succeeds).
  bool connected() const noexcept { return connected_; }

  /// Reads `count` (1..125) registers from `table` starting at `address` into `dest`.
  /// ok, or a status from the error mapping; wrong_state when not open; invalid_argument for a
  /// count out of range. Bounded as described at the top.
  hal::HalStatus read_registers(RegisterTable table, int address, int count, std::uint16_t* dest) noexcept;
  /// Writes `count` (1..123) registers starting at `address` with FC16.
  hal::HalStatus write_registers(int address, int count, const std::uint16_t* values) noexcept;

  const ModbusLinkCounters& counters() const noexcept { return counters_; }
  const ModbusLinkConfig& config() const noexcept { return config_; }

 private:
  hal::HalStatus ensure_connected() noexcept;
  hal::HalStatus fail(int err) noexcept;
  void prepare() noexcept;

  const hal::Clock& clock_;
  ModbusLinkConfig config_;
  ::_modbus* ctx_ = nullptr;
  bool connected_ = false;
  bool needs_flush_ = false;
  double last_attempt_s_ = 0;
  ModbusLinkCounters counters_;
};

}  // namespace pliant::drivers::modbus
