#include "pliant/drivers/modbus/robotiq_ft300.hpp"

#include <unistd.h>

#include <cerrno>
#include <cmath>

#include "serial_port.hpp"

namespace pliant::drivers::modbus {
namespace {

using hal::HalStatus;

constexpr std::size_t kChunk = 64;

bool finite_non_negative(double v) noexcept { return std::isfinite(v) && v >= 0; }

bool port_gone(int err) noexcept { return err == EIO || err == ENXIO || err == ENODEV || err == EBADF; }

}  // namespace

RobotiqFt300::RobotiqFt300(const hal::Clock& clock, const RobotiqFt300Config& config)
    : clock_(clock), config_(config), link_(clock) {}

RobotiqFt300::~RobotiqFt300() { close_port(); }

HalStatus RobotiqFt300::on_configure() {
  const RobotiqFt300Config& c = config_;
  if (validate(c.link) != HalStatus::ok || !finite_non_negative(c.min_poll_period_s) ||
      !(std::isfinite(c.stream_timeout_s) && c.stream_timeout_s > 0) ||
      c.max_stream_bytes_per_read < ft300::kFrameSize || c.max_stream_bytes_per_read > 65536) {
    return HalStatus::invalid_argument;
  }
  close_port();
  link_.close();
  parser_.reset();
  port_down_ = false;
  delivered_frames_ = 0;
  crc_errors_seen_ = 0;
  polled_ = false;
  sequence_ = 0;
  tare_requested_ = false;
  for (double& b : bias_) b = 0;
  counters_ = RobotiqFt300Counters{};
  if (c.mode == Ft300Mode::polling) return link_.open(c.link);
  if (c.mode != Ft300Mode::stream || c.link.transport != ModbusTransport::rtu ||
      !detail::serial_baud_supported(c.link.baud)) {
    return HalStatus::invalid_argument;
  }
  return open_port();
}

HalStatus RobotiqFt300::on_start() noexcept {
  if (config_.mode == Ft300Mode::polling) return HalStatus::ok;
  if (fd_ < 0) {
    const HalStatus s = open_port();
    if (s != HalStatus::ok) return s;
  }
  port_down_ = false;
  const HalStatus s = send_start();
  if (s != HalStatus::ok) {
    close_port();
    return s;
  }
  last_frame_s_ = clock_.now_s();
  return HalStatus::ok;
}

HalStatus RobotiqFt300::on_stop() noexcept {
  if (config_.mode != Ft300Mode::stream || fd_ < 0) return HalStatus::ok;
  std::uint8_t jam[ft300::kJamLength];
  for (std::uint8_t& b : jam) b = ft300::kJamByte;
  int err = 0;
  // Best effort: stopping cannot be refused (device.hpp); a failed jam is reported, not retried.
  return detail::write_now(fd_, jam, sizeof jam, err) ? HalStatus::ok : HalStatus::io_error;
}

HalStatus RobotiqFt300::on_cleanup() noexcept {
  close_port();
  link_.close();
  return HalStatus::ok;
}

HalStatus RobotiqFt300::on_read(hal::WrenchReading& out) noexcept {
  return config_.mode == Ft300Mode::polling ? read_polling(out) : read_stream(out);
}

void RobotiqFt300::deliver(const double raw[6], std::uint64_t sequence, std::uint32_t bits,
                           hal::WrenchReading& out) noexcept {
  if (tare_requested_) {
    for (int i = 0; i < 6; ++i) bias_[i] = raw[i];
    tare_requested_ = false;
    ++counters_.tares;
  }
  hal::WrenchReading r;
  for (int i = 0; i < 6; ++i) r.wrench[i] = raw[i] - bias_[i];
  r.header.stamp_s = clock_.now_s();
  r.header.sequence = sequence;
  r.header.status_bits = bits;
  out = r;
}

HalStatus RobotiqFt300::read_polling(hal::WrenchReading& out) noexcept {
  const double now = clock_.now_s();
  if (polled_ && config_.min_poll_period_s > 0 && now - last_poll_s_ < config_.min_poll_period_s) {
    ++counters_.polls_skipped;
    return HalStatus::no_data;
  }
  polled_ = true;
  last_poll_s_ = now;
  std::uint16_t registers[ft300::kWrenchRegisterCount] = {0, 0, 0, 0, 0, 0};
  const HalStatus s =
      link_.read_registers(RegisterTable::holding, ft300::kWrenchRegister, ft300::kWrenchRegisterCount, registers);
  if (s == HalStatus::unsupported) return HalStatus::io_error;
  if (s != HalStatus::ok) return s;
  double raw[6];
  ft300::registers_to_wrench(registers, raw);
  deliver(raw, ++sequence_, 0, out);
  return HalStatus::ok;
}

HalStatus RobotiqFt300::open_port() noexcept {
  int err = 0;
  fd_ = detail::open_serial_port(config_.link.device.c_str(), config_.link.baud, err);
  if (fd_ >= 0) return HalStatus::ok;
  const HalStatus s = modbus_errno_status(err);
  return s == HalStatus::disconnected || s == HalStatus::timeout ? s : HalStatus::io_error;
}

void RobotiqFt300::close_port() noexcept {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
}

HalStatus RobotiqFt300::send_start() noexcept {
  std::uint8_t request[ft300::kStartRequestSize];
  ft300::encode_stream_start_request(static_cast<std::uint8_t>(config_.link.slave_id), request);
  int err = 0;
  if (!detail::write_now(fd_, request, sizeof request, err)) {
    return port_gone(err) ? HalStatus::disconnected : HalStatus::io_error;
  }
  ++counters_.stream_starts;
  return HalStatus::ok;
}

HalStatus RobotiqFt300::port_lost() noexcept {
  close_port();
  port_down_ = true;
  port_down_since_s_ = clock_.now_s();
  return HalStatus::disconnected;
}

HalStatus RobotiqFt300::read_stream(hal::WrenchReading& out) noexcept {
  const double now = clock_.now_s();
  if (port_down_) {
    if (now - port_down_since_s_ < config_.link.reconnect_interval_s) return HalStatus::disconnected;
    ++counters_.reconnect_attempts;
    port_down_since_s_ = now;
    if (open_port() != HalStatus::ok) return HalStatus::disconnected;
    if (send_start() != HalStatus::ok) return port_lost();
    port_down_ = false;
    ++counters_.reconnects;
    last_frame_s_ = now;
  }
  std::uint8_t chunk[kChunk];
  std::size_t total = 0;
  const std::size_t limit = config_.max_stream_bytes_per_read;
  // At most limit / kChunk + 1 passes that read data, and EINTR retries bounded the same way.
  for (std::size_t pass = 0; total < limit && pass <= limit / kChunk + 1; ++pass) {
    const std::size_t want = limit - total < kChunk ? limit - total : kChunk;
    const ssize_t n = ::read(fd_, chunk, want);
    if (n > 0) {
      parser_.feed(chunk, static_cast<std::size_t>(n));
      total += static_cast<std::size_t>(n);
      continue;
    }
    if (n == 0) return port_lost();  // end of file: the tty hung up
    const int err = errno;
    if (err == EAGAIN || err == EWOULDBLOCK) break;
    if (err == EINTR) continue;
    if (port_gone(err)) return port_lost();
    return HalStatus::io_error;
  }
  const ft300::StreamParserCounters& pc = parser_.counters();
  if (pc.frames > delivered_frames_) {
    delivered_frames_ = pc.frames;
    const std::uint32_t bits = pc.crc_errors > crc_errors_seen_ ? hal::kFtCanBusError : 0u;
    crc_errors_seen_ = pc.crc_errors;
    last_frame_s_ = now;
    deliver(parser_.latest().wrench, pc.frames, bits, out);
    return HalStatus::ok;
  }
  if (now - last_frame_s_ >= config_.stream_timeout_s) {
    ++counters_.stream_timeouts;
    return HalStatus::timeout;
  }
  return HalStatus::no_data;
}

}  // namespace pliant::drivers::modbus
