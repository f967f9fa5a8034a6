#include "pliant/drivers/modbus/robotiq_2f_codec.hpp"

#include <cmath>
#include <limits>

namespace pliant::drivers::modbus::robotiq2f {
namespace {

constexpr std::uint16_t pack(std::uint8_t high, std::uint8_t low) noexcept {
  return static_cast<std::uint16_t>((static_cast<unsigned>(high) << 8) | low);
}
constexpr std::uint8_t high_byte(std::uint16_t r) noexcept { return static_cast<std::uint8_t>(r >> 8); }
constexpr std::uint8_t low_byte(std::uint16_t r) noexcept { return static_cast<std::uint8_t>(r & 0xffu); }

bool valid_range(double lo, double hi) noexcept { return std::isfinite(lo) && std::isfinite(hi) && lo >= 0 && hi > lo; }

// round(255 * (v - lo) / (hi - lo)) clamped to 0..255; NaN gives 0. Works for hi <= lo too
// (never divides by zero: an empty range maps everything to 0).
std::uint8_t to_byte(double v, double lo, double hi) noexcept {
  if (std::isnan(v) || !(hi > lo)) return 0;
  const double x = 255.0 * (v - lo) / (hi - lo);
  if (!(x > 0)) return 0;
  if (x >= 255) return 255;
  return static_cast<std::uint8_t>(std::lround(x));
}

double from_byte(std::uint8_t b, double lo, double hi) noexcept {
  return lo + (hi - lo) * static_cast<double>(b) / 255.0;
}

}  // namespace

void encode_command(const Command& command, std::uint16_t registers[kRegisterCount]) noexcept {
  registers[0] = pack(command.action, 0);
  registers[1] = pack(0, command.position);
  registers[2] = pack(command.speed, command.force);
}

Command decode_command(const std::uint16_t registers[kRegisterCount]) noexcept {
  Command c;
  c.action = high_byte(registers[0]);
  c.position = low_byte(registers[1]);
  c.speed = high_byte(registers[2]);
  c.force = low_byte(registers[2]);
  return c;
}

Status decode_status(const std::uint16_t registers[kRegisterCount]) noexcept {
  const std::uint8_t b0 = high_byte(registers[0]);
  const std::uint8_t b2 = high_byte(registers[1]);
  Status s;
  s.gact = static_cast<std::uint8_t>(b0 & 0x01u);
  s.ggto = static_cast<std::uint8_t>((b0 >> 3) & 0x01u);
  s.gsta = static_cast<std::uint8_t>((b0 >> 4) & 0x03u);
  s.gobj = static_cast<std::uint8_t>((b0 >> 6) & 0x03u);
  s.reserved = low_byte(registers[0]);
  s.gflt = static_cast<std::uint8_t>(b2 & 0x0fu);
  s.kflt = static_cast<std::uint8_t>(b2 >> 4);
  s.position_request = low_byte(registers[1]);
  s.position = high_byte(registers[2]);
  s.current = low_byte(registers[2]);
  return s;
}

void encode_status(const Status& s, std::uint16_t registers[kRegisterCount]) noexcept {
  const auto b0 = static_cast<std::uint8_t>((s.gact & 0x01u) | ((s.ggto & 0x01u) << 3) | ((s.gsta & 0x03u) << 4) |
                                            ((s.gobj & 0x03u) << 6));
  const auto b2 = static_cast<std::uint8_t>((s.gflt & 0x0fu) | ((s.kflt & 0x0fu) << 4));
  registers[0] = pack(b0, s.reserved);
  registers[1] = pack(b2, s.position_request);
  registers[2] = pack(s.position, s.current);
}

std::uint32_t status_bits(const Status& s) noexcept {
  std::uint32_t bits = 0;
  if (is_activated(s)) bits |= hal::kGripperActivated;
  if (s.ggto == 1) {
    if (s.gobj == kObjMoving) bits |= hal::kGripperMoving;
    if (s.gobj == kObjContactClosing) bits |= hal::kGripperObjectDetected;
    if (s.gobj == kObjAtPosition) bits |= hal::kGripperAtTarget;
  }
  const std::uint32_t fault = (static_cast<std::uint32_t>(s.kflt & 0x0fu) << 4) | (s.gflt & 0x0fu);
  bits |= fault << hal::kGripperFaultCodeShift;
  return bits;
}

hal::HalStatus validate(const Scaling& c) noexcept {
  if (!(std::isfinite(c.stroke_m) && c.stroke_m > 0) || c.open_byte == c.closed_byte ||
      !valid_range(c.min_speed_m_per_s, c.max_speed_m_per_s) || !valid_range(c.min_force_n, c.max_force_n)) {
    return hal::HalStatus::invalid_argument;
  }
  return hal::HalStatus::ok;
}

double position_to_width(std::uint8_t p, const Scaling& c) noexcept {
  const double span = static_cast<double>(c.closed_byte) - static_cast<double>(c.open_byte);
  if (span == 0 || !(c.stroke_m > 0)) return std::numeric_limits<double>::quiet_NaN();
  // The byte fraction first: stroke x (closed - p) overflows for strokes near DBL_MAX.
  const double w = c.stroke_m * ((static_cast<double>(c.closed_byte) - static_cast<double>(p)) / span);
  if (w < 0) return 0;
  if (w > c.stroke_m) return c.stroke_m;
  return w;
}

std::uint8_t width_to_position(double width_m, const Scaling& c) noexcept {
  if (std::isnan(width_m) || !(c.stroke_m > 0)) return c.open_byte;  // also NaN stroke
  double w = width_m;
  if (w < 0) w = 0;
  if (w > c.stroke_m) w = c.stroke_m;
  const double closed = static_cast<double>(c.closed_byte);
  const double open = static_cast<double>(c.open_byte);
  const double p = closed - (closed - open) * (w / c.stroke_m);  // between open and closed
  if (!std::isfinite(p)) return c.open_byte;                     // an infinite stroke (invalid scaling)
  const long r = std::lround(p);
  if (r < 0) return 0;
  if (r > 255) return 255;
  return static_cast<std::uint8_t>(r);
}

std::uint8_t speed_to_byte(double speed_m_per_s, const Scaling& c) noexcept {
  return to_byte(speed_m_per_s, c.min_speed_m_per_s, c.max_speed_m_per_s);
}

double byte_to_speed(std::uint8_t b, const Scaling& c) noexcept {
  return from_byte(b, c.min_speed_m_per_s, c.max_speed_m_per_s);
}

std::uint8_t force_to_byte(double force_n, const Scaling& c) noexcept {
  return to_byte(force_n, c.min_force_n, c.max_force_n);
}

double byte_to_force(std::uint8_t b, const Scaling& c) noexcept { return from_byte(b, c.min_force_n, c.max_force_n); }

void to_reading(const Status& s, const Scaling& scaling, hal::GripperReading& out) noexcept {
  out.header.status_bits = status_bits(s);
  out.width_m = position_to_width(s.position, scaling);
  out.target_width_m = position_to_width(s.position_request, scaling);
  out.current_a = current_from_byte(s.current);
  out.force_n = std::numeric_limits<double>::quiet_NaN();
}

}  // namespace pliant::drivers::modbus::robotiq2f
