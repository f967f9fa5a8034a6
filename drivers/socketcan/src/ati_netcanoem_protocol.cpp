#include "pliant/drivers/socketcan/ati_netcanoem_protocol.hpp"

#include <cmath>
#include <cstring>

namespace pliant::drivers::socketcan::ati {

namespace {

// Unit conversions (exact by definition: 1 lbf = 4.4482216152605 N, 1 in = 0.0254 m,
// 1 kgf = 9.80665 N).
constexpr double kLbf = 4.4482216152605;
constexpr double kKgf = 9.80665;

}  // namespace

CanFrame make_request(std::uint8_t base_id, Opcode op, std::uint8_t arg) noexcept {
  const bool has_arg = op == Opcode::read_matrix || op == Opcode::set_calibration || op == Opcode::read_adc ||
                       op == Opcode::set_base_id || op == Opcode::set_baud;
  return make_standard_frame(can_id(base_id, op), &arg, has_arg ? 1 : 0);
}

const char* decode_error_name(DecodeError e) noexcept {
  switch (e) {
    case DecodeError::none: return "none";
    case DecodeError::foreign_id: return "foreign_id";
    case DecodeError::unknown_opcode: return "unknown_opcode";
    case DecodeError::wrong_dlc: return "wrong_dlc";
  }
  return "unknown";
}

std::uint8_t response_dlc(Opcode op) noexcept {
  switch (op) {
    case Opcode::read_gauges: return 8;
    case Opcode::gauges_second: return 6;
    case Opcode::read_matrix:
    case Opcode::matrix_second:
    case Opcode::matrix_third: return 8;
    case Opcode::read_serial: return 8;
    case Opcode::set_calibration: return 1;
    case Opcode::read_counts: return 8;
    case Opcode::read_units: return 2;
    case Opcode::read_adc: return 2;
    case Opcode::set_base_id:
    case Opcode::set_baud: return 1;
    case Opcode::read_firmware: return 4;
    case Opcode::reset: return 0;
  }
  return 0;
}

DecodeError decode_response(const CanFrame& frame, std::uint8_t base_id, Response& out) noexcept {
  if (!is_standard_data_frame(frame) || (frame.id >> 4) != (static_cast<std::uint32_t>(base_id) & kMaxBaseId)) {
    return DecodeError::foreign_id;
  }
  const unsigned code = frame.id & 0xfu;
  if (code == 0xa || code == 0xb || code == 0xc) return DecodeError::unknown_opcode;
  const auto op = static_cast<Opcode>(code);
  const std::uint8_t* d = frame.data;
  const bool ack = op == Opcode::set_base_id || op == Opcode::set_baud;
  if (ack ? frame.dlc > 1 : frame.dlc != response_dlc(op)) return DecodeError::wrong_dlc;
  Response r;
  r.opcode = op;
  switch (op) {
    case Opcode::read_gauges:
      r.status = load_be_u16(d);
      for (int i = 0; i < 3; ++i) r.gauges[i] = load_be_i16(d + 2 + 2 * i);
      break;
    case Opcode::gauges_second:
      for (int i = 0; i < 3; ++i) r.gauges[i] = load_be_i16(d + 2 * i);
      break;
    case Opcode::read_matrix:
    case Opcode::matrix_second:
    case Opcode::matrix_third:
      r.matrix[0] = load_be_f32(d);
      r.matrix[1] = load_be_f32(d + 4);
      break;
    case Opcode::read_serial: std::memcpy(r.serial, d, 8); break;
    case Opcode::set_calibration: r.byte = d[0]; break;
    case Opcode::read_counts:
      r.counts_per_force = load_be_u32(d);
      r.counts_per_torque = load_be_u32(d + 4);
      break;
    case Opcode::read_units:
      r.force_unit = d[0];
      r.torque_unit = d[1];
      break;
    case Opcode::read_adc: r.adc = load_be_u16(d); break;
    case Opcode::set_base_id:
    case Opcode::set_baud: r.byte = frame.dlc == 1 ? d[0] : 0; break;
    case Opcode::read_firmware:
      r.firmware_major = d[0];
      r.firmware_minor = d[1];
      r.firmware_build = load_be_u16(d + 2);
      break;
    case Opcode::reset: return DecodeError::unknown_opcode;
  }
  out = r;
  return DecodeError::none;
}

bool GaugeAssembler::reset() noexcept {
  const bool held = have_ != 0;
  have_ = 0;
  return held;
}

GaugeAssembler::Result GaugeAssembler::add(const Response& r) noexcept {
  std::uint8_t bit = 0;
  if (r.opcode == Opcode::read_gauges) {
    bit = 1;
  } else if (r.opcode == Opcode::gauges_second) {
    bit = 2;
  } else {
    return Result::ignored;
  }
  const bool replaced = (have_ & bit) != 0;
  if (bit == 1) {
    // Frame 0x0: status, SG0, SG2, SG4.
    pending_.status = r.status;
    pending_.gauges[0] = r.gauges[0];
    pending_.gauges[2] = r.gauges[1];
    pending_.gauges[4] = r.gauges[2];
  } else {
    // Frame 0x1: SG1, SG3, SG5.
    pending_.gauges[1] = r.gauges[0];
    pending_.gauges[3] = r.gauges[1];
    pending_.gauges[5] = r.gauges[2];
  }
  if (replaced) {
    // The other half, if held, belongs to the older copy; start over with this frame.
    have_ = bit;
    return Result::replaced;
  }
  have_ = static_cast<std::uint8_t>(have_ | bit);
  if (have_ != 3) return Result::partial;
  sample_ = pending_;
  have_ = 0;
  return Result::complete;
}

double force_unit_to_newton(std::uint8_t code) noexcept {
  switch (code) {
    case 1: return kLbf;
    case 2: return 1.0;
    case 3: return 1000.0 * kLbf;
    case 4: return 1000.0;
    case 5: return kKgf;
    case 6: return kKgf / 1000.0;
    default: return 0.0;
  }
}

double torque_unit_to_newton_metre(std::uint8_t code) noexcept {
  switch (code) {
    case 1: return kLbf * 0.0254;
    case 2: return kLbf * 0.3048;
    case 3: return 1.0;
    case 4: return 0.001;
    case 5: return kKgf * 0.01;
    case 6: return 1000.0;
    default: return 0.0;
  }
}

const char* calibration_error_name(CalibrationError e) noexcept {
  switch (e) {
    case CalibrationError::none: return "none";
    case CalibrationError::non_finite_matrix: return "non_finite_matrix";
    case CalibrationError::zero_counts: return "zero_counts";
    case CalibrationError::unknown_force_unit: return "unknown_force_unit";
    case CalibrationError::unknown_torque_unit: return "unknown_torque_unit";
  }
  return "unknown";
}

CalibrationError check(const Calibration& c) noexcept {
  for (float v : c.matrix) {
    if (!std::isfinite(v)) return CalibrationError::non_finite_matrix;
  }
  if (c.counts_per_force == 0 || c.counts_per_torque == 0) return CalibrationError::zero_counts;
  if (force_unit_to_newton(c.force_unit) == 0.0) return CalibrationError::unknown_force_unit;
  if (torque_unit_to_newton_metre(c.torque_unit) == 0.0) return CalibrationError::unknown_torque_unit;
  return CalibrationError::none;
}

CalibrationError make_scaling(const Calibration& c, Scaling& out) noexcept {
  const CalibrationError e = check(c);
  if (e != CalibrationError::none) return e;
  const double force_scale = force_unit_to_newton(c.force_unit) / static_cast<double>(c.counts_per_force);
  const double torque_scale = torque_unit_to_newton_metre(c.torque_unit) / static_cast<double>(c.counts_per_torque);
  for (int r = 0; r < 6; ++r) {
    const double s = r < 3 ? force_scale : torque_scale;
    for (int k = 0; k < 6; ++k) out.matrix[6 * r + k] = static_cast<double>(c.matrix[6 * r + k]) * s;
  }
  return CalibrationError::none;
}

void gauges_to_wrench(const Scaling& scaling, const std::int16_t gauges[6], const double bias[6],
                      double wrench[6]) noexcept {
  double g[6];
  for (int k = 0; k < 6; ++k) g[k] = static_cast<double>(gauges[k]) - bias[k];
  for (int r = 0; r < 6; ++r) {
    double acc = 0;
    for (int k = 0; k < 6; ++k) acc += scaling.matrix[6 * r + k] * g[k];
    wrench[r] = acc;
  }
}

}  // namespace pliant::drivers::socketcan::ati
