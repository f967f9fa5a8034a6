// pliant modbus driver: a Robotiq FT 300 wrist sensor as a pliant::hal::ForceTorqueSensor.
// Protocol facts and scales: ft300_codec.hpp (sources: docs/drivers/modbus.md).
//
// Two modes:
//   polling  every read() is one FC03 transaction of registers 180..185 over the ModbusLink
//            (RTU, default 19200 8N1 slave 9, or TCP through a gateway / the emulator). A read
//            waits at most link.response_timeout_s (default 20 ms); min_poll_period_s rate-limits
//            the polls (no_data in between, no I/O). Errors are the link's (modbus_link.hpp):
//            timeout, disconnected (reconnects on a later read, at most once per
//            link.reconnect_interval_s), io_error.
//   stream   configure opens link.device as a raw serial port (link.baud, 8N1, non-blocking;
//            any tty, a pseudo-terminal included); start() writes the RTU request "0x0200 to
//            register 410" itself and does not wait for its answer (the answer, if any, is
//            skipped by the frame parser as garbage). read() drains at most
//            max_stream_bytes_per_read bytes that are already there (non-blocking read(2),
//            never waits), feeds ft300::StreamParser and delivers the newest complete frame:
//            ok, or no_data when no new frame arrived. sequence = the parser's frame count, so
//            frames that arrived between two reads show up as dropped samples in the hal
//            counters. While no valid frame came for stream_timeout_s, every read returns
//            timeout (until the next frame). read(2) end-of-file or EIO/ENXIO/ENODEV ->
//            disconnected: the port is closed, reopened on a later read (at most once per
//            link.reconnect_interval_s) and the start request is sent again. stop() writes the 50-byte jam signal once
//            (non-blocking); the sensor may need it repeated, and Modbus on that port answers
//            only ~100 ms after the stream stopped (docs/drivers/modbus.md) - this driver
//            never mixes the two modes on one port.
//
// Samples: wrench minus the bias (request_tare() takes the next sample's raw wrench as the
// bias; cleared by configure), stamped with the clock time of the read that delivered it. Status
// bits: the FT 300 reports no status word. In stream mode kFtCanBusError ("transport degraded",
// not in kFtFaultMask) is set on a sample when the parser counted CRC errors since the previous
// sample.
// Bounds: polling read <= 1 transaction; stream read = one read(2) per 64-byte chunk, at most
// max_stream_bytes_per_read bytes. No allocation, no exceptions after configure.
// Thread safety: drive one instance from one thread.
#pragma once

#include <cstddef>
#include <cstdint>

#include "pliant/drivers/modbus/ft300_codec.hpp"
#include "pliant/drivers/modbus/modbus_link.hpp"
#include "pliant/hal/clock.hpp"
#include "pliant/hal/force_torque.hpp"

namespace pliant::drivers::modbus {

enum class Ft300Mode : std::uint8_t { polling, stream };

struct RobotiqFt300Config {
  Ft300Mode mode = Ft300Mode::polling;
  /// Polling: the Modbus link. Stream: device, baud, slave_id and reconnect_interval_s are used
  /// (transport must be rtu). Default baud here is the FT 300's 19200.
  ModbusLinkConfig link = default_link();
  double min_poll_period_s = 0.0;               ///< polling, >= 0
  double stream_timeout_s = 0.16;               ///< stream: no valid frame this long -> timeout, > 0
  std::size_t max_stream_bytes_per_read = 512;  ///< stream, 16..65536
  /// The FT 300's link defaults: RTU, /dev/ttyUSB0, 19200 8N1, slave 9, 20 ms.
  static ModbusLinkConfig default_link() {
    ModbusLinkConfig c;
    c.baud = ft300::kDefaultBaud;
    c.slave_id = ft300::kDefaultSlaveId;
    return c;
  }
};

/// Driver counters beyond hal::DeviceCounters (reset by configure).
struct RobotiqFt300Counters {
  std::uint64_t polls_skipped = 0;       ///< polling reads answered no_data by min_poll_period_s
  std::uint64_t stream_starts = 0;       ///< start requests written
  std::uint64_t stream_timeouts = 0;     ///< reads that returned timeout for stream silence
  std::uint64_t reconnect_attempts = 0;  ///< stream: tries to reopen the port
  std::uint64_t reconnects = 0;          ///< stream: reopen + start request that succeeded
  std::uint64_t tares = 0;               ///< biases taken
};

class RobotiqFt300 final : public hal::ForceTorqueSensor {
 public:
  RobotiqFt300(const hal::Clock& clock, const RobotiqFt300Config& config);
  ~RobotiqFt300() override;

  /// The next delivered sample becomes the bias (that sample reads zero). Allocation-free.
  void request_tare() noexcept { tare_requested_ = true; }
  /// Current bias (N, N m); zeros until a tare.
  const double* bias() const noexcept { return bias_; }

  const RobotiqFt300Counters& driver_counters() const noexcept { return counters_; }
  /// Polling mode: the link's counters.
  const ModbusLinkCounters& link_counters() const noexcept { return link_.counters(); }
  /// Stream mode: the frame parser's counters (frames, CRC errors, garbage bytes).
  const ft300::StreamParserCounters& stream_counters() const noexcept { return parser_.counters(); }
  const RobotiqFt300Config& config() const noexcept { return config_; }

 protected:
  hal::HalStatus on_configure() override;
  hal::HalStatus on_start() noexcept override;
  hal::HalStatus on_stop() noexcept override;
  hal::HalStatus on_cleanup() noexcept override;
  hal::HalStatus on_read(hal::WrenchReading& out) noexcept override;

 private:
  hal::HalStatus read_polling(hal::WrenchReading& out) noexcept;
  hal::HalStatus read_stream(hal::WrenchReading& out) noexcept;
  hal::HalStatus open_port() noexcept;
  void close_port() noexcept;
  hal::HalStatus send_start() noexcept;
  hal::HalStatus port_lost() noexcept;
  void deliver(const double raw[6], std::uint64_t sequence, std::uint32_t bits, hal::WrenchReading& out) noexcept;

  const hal::Clock& clock_;
  RobotiqFt300Config config_;
  ModbusLink link_;
  ft300::StreamParser parser_;
  int fd_ = -1;
  bool port_down_ = false;
  double port_down_since_s_ = 0;
  double last_frame_s_ = 0;
  std::uint64_t delivered_frames_ = 0;
  std::uint64_t crc_errors_seen_ = 0;
  bool polled_ = false;
  double last_poll_s_ = 0;
  std::uint64_t sequence_ = 0;
  bool tare_requested_ = false;
  double bias_[6] = {0, 0, 0, 0, 0, 0};
  RobotiqFt300Counters counters_;
};

}  // namespace pliant::drivers::modbus
