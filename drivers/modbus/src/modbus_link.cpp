#include "pliant/drivers/modbus/modbus_link.hpp"

#include <arpa/inet.h>
#include <modbus.h>

#include <cerrno>
#include <cmath>

namespace pliant::drivers::modbus {
namespace {

using hal::HalStatus;

bool is_modbus_exception(int err) noexcept {
  return err > MODBUS_ENOBASE && err < MODBUS_ENOBASE + MODBUS_EXCEPTION_MAX;
}

// Seconds -> libmodbus's (sec, usec) pair; the caller validated 0 < s <= 10.
void split_seconds(double s, std::uint32_t& sec, std::uint32_t& usec) noexcept {
  const auto total_us = static_cast<std::uint64_t>(std::llround(s * 1e6));
  sec = static_cast<std::uint32_t>(total_us / 1000000u);
  usec = static_cast<std::uint32_t>(total_us % 1000000u);
  if (sec == 0 && usec == 0) usec = 1;  // (0, 0) would mean "no timeout" for some calls
}

}  // namespace

HalStatus validate(const ModbusLinkConfig& c) noexcept {
  if (!(std::isfinite(c.response_timeout_s) && c.response_timeout_s > 0 && c.response_timeout_s <= 10) ||
      !(std::isfinite(c.reconnect_interval_s) && c.reconnect_interval_s >= 0) || c.slave_id < 0 || c.slave_id > 247) {
    return HalStatus::invalid_argument;
  }
  if (c.transport == ModbusTransport::rtu) {
    if (c.device.empty() || c.baud <= 0 || (c.parity != 'N' && c.parity != 'E' && c.parity != 'O') || c.data_bits < 5 ||
        c.data_bits > 8 || (c.stop_bits != 1 && c.stop_bits != 2)) {
      return HalStatus::invalid_argument;
    }
    return HalStatus::ok;
  }
  if (c.transport == ModbusTransport::tcp) {
    in_addr address{};
    if (c.port < 1 || c.port > 65535 || inet_pton(AF_INET, c.host.c_str(), &address) != 1) {
      return HalStatus::invalid_argument;
    }
    return HalStatus::ok;
  }
  return HalStatus::invalid_argument;
}

HalStatus modbus_errno_status(int err) noexcept {
  switch (err) {
    case ETIMEDOUT:
    case EMBXGTAR: return HalStatus::timeout;
    case ECONNRESET:
    case ECONNREFUSED:
    case ECONNABORTED:
    case EPIPE:
    case ENOTCONN:
    case EBADF:
    case EIO:
    case ENXIO:
    case ENODEV:
    case ENOENT:
    case EACCES:
    case EHOSTUNREACH:
    case ENETUNREACH:
    case ENETDOWN:
    case EHOSTDOWN: return HalStatus::disconnected;
    case EMBXILFUN: return HalStatus::unsupported;
    default: return HalStatus::io_error;
  }
}

ModbusLink::~ModbusLink() { close(); }

HalStatus ModbusLink::open(const ModbusLinkConfig& config) {
  close();
  const HalStatus valid = validate(config);
  if (valid != HalStatus::ok) return valid;
  config_ = config;
  counters_ = ModbusLinkCounters{};
  errno = 0;
  if (config.transport == ModbusTransport::rtu) {
    ctx_ = modbus_new_rtu(config.device.c_str(), config.baud, config.parity, config.data_bits, config.stop_bits);
  } else {
    ctx_ = modbus_new_tcp(config.host.c_str(), config.port);
  }
  if (ctx_ == nullptr) return errno == ENOMEM ? HalStatus::capacity_exceeded : HalStatus::invalid_argument;
  std::uint32_t sec = 0, usec = 0;
  split_seconds(config.response_timeout_s, sec, usec);
  if (modbus_set_slave(ctx_, config.slave_id) != 0 || modbus_set_response_timeout(ctx_, sec, usec) != 0 ||
      modbus_set_byte_timeout(ctx_, 0, 0) != 0 || modbus_set_error_recovery(ctx_, MODBUS_ERROR_RECOVERY_NONE) != 0) {
    close();
    return HalStatus::invalid_argument;
  }
  if (modbus_connect(ctx_) != 0) {
    const int err = errno;
    counters_.last_errno = err;
    close();
    const HalStatus s = modbus_errno_status(err);
    return s == HalStatus::ok || s == HalStatus::unsupported ? HalStatus::io_error : s;
  }
  connected_ = true;
  needs_flush_ = false;
  last_attempt_s_ = clock_.now_s();
  return HalStatus::ok;
}

void ModbusLink::close() noexcept {
  if (ctx_ != nullptr) {
    if (connected_) modbus_close(ctx_);
    modbus_free(ctx_);
    ctx_ = nullptr;
  }
  connected_ = false;
  needs_flush_ = false;
}

HalStatus ModbusLink::ensure_connected() noexcept {
  if (connected_) return HalStatus::ok;
  const double now = clock_.now_s();
  if (now - last_attempt_s_ < config_.reconnect_interval_s) return HalStatus::disconnected;
  last_attempt_s_ = now;
  ++counters_.reconnect_attempts;
  if (modbus_connect(ctx_) != 0) {
    counters_.last_errno = errno;
    modbus_close(ctx_);
    return HalStatus::disconnected;
  }
  connected_ = true;
  needs_flush_ = false;
  ++counters_.reconnects;
  return HalStatus::ok;
}

void ModbusLink::prepare() noexcept {
  if (!needs_flush_) return;
  modbus_flush(ctx_);
  ++counters_.flushes;
  needs_flush_ = false;
}

HalStatus ModbusLink::fail(int err) noexcept {
  ++counters_.failures;
  counters_.last_errno = err;
  const HalStatus status = modbus_errno_status(err);
  switch (status) {
    case HalStatus::timeout:
      ++counters_.timeouts;
      needs_flush_ = true;
      break;
    case HalStatus::disconnected:
      if (connected_) ++counters_.disconnects;
      connected_ = false;
      needs_flush_ = false;
      modbus_close(ctx_);
      last_attempt_s_ = clock_.now_s();
      break;
    case HalStatus::unsupported: ++counters_.exceptions; break;
    default:
      if (is_modbus_exception(err)) {
        ++counters_.exceptions;
      } else {
        ++counters_.bad_responses;
        needs_flush_ = true;
      }
      break;
  }
  return status;
}

HalStatus ModbusLink::read_registers(RegisterTable table, int address, int count, std::uint16_t* dest) noexcept {
  if (ctx_ == nullptr) return HalStatus::wrong_state;
  if (count < 1 || count > MODBUS_MAX_READ_REGISTERS || address < 0 || address + count > 65536 || dest == nullptr) {
    return HalStatus::invalid_argument;
  }
  const HalStatus link = ensure_connected();
  if (link != HalStatus::ok) return link;
  prepare();
  ++counters_.transactions;
  errno = 0;
  const int rc = table == RegisterTable::input ? modbus_read_input_registers(ctx_, address, count, dest)
                                               : modbus_read_registers(ctx_, address, count, dest);
  if (rc == count) return HalStatus::ok;
  return fail(rc < 0 ? errno : EMBBADDATA);
}

HalStatus ModbusLink::write_registers(int address, int count, const std::uint16_t* values) noexcept {
  if (ctx_ == nullptr) return HalStatus::wrong_state;
  if (count < 1 || count > MODBUS_MAX_WRITE_REGISTERS || address < 0 || address + count > 65536 || values == nullptr) {
    return HalStatus::invalid_argument;
  }
  const HalStatus link = ensure_connected();
  if (link != HalStatus::ok) return link;
  prepare();
  ++counters_.transactions;
  errno = 0;
  const int rc = modbus_write_registers(ctx_, address, count, values);
  if (rc == count) return HalStatus::ok;
  return fail(rc < 0 ? errno : EMBBADDATA);
}

}  // namespace pliant::drivers::modbus
