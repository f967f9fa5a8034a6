// pliant socketcan driver: the ATI F/T NETCANOEM CAN protocol, pure (no I/O).
// Source: the ATI Net CAN OEM manual (ATI 9610-05-1030) as implemented by three independent
// drivers (TRI, KIT, griloHBG); per-fact sources in docs/drivers/socketcan.md, "Device facts we
// rely on".
//
// Addressing: a sensor has a 7-bit base ID (0..0x7F); every frame, request or response, has the
// standard 11-bit ID (base_id << 4) | opcode, opcode 4 bits. All multi-byte fields are
// big-endian; calibration values are IEEE-754 binary32.
//
//   op   request (payload)          response frames (opcode: payload)
//   0x0  READ_SG (none)             0x0: status u16, SG0 i16, SG2 i16, SG4 i16 (DLC 8)
//                                   0x1: SG1 i16, SG3 i16, SG5 i16            (DLC 6)
//   0x2  READ_MATRIX (axis u8 0..5) 0x2: M[r][0] f32, M[r][1] f32; 0x3: M[r][2..3]; 0x4: M[r][4..5]
//   0x5  READ_SERIAL (none)         0x5: 8 ASCII bytes
//   0x6  SET_CALIBRATION (idx 0..15) 0x6: idx u8 (echo)
//   0x7  READ_COUNTS (none)         0x7: counts_per_force u32, counts_per_torque u32
//   0x8  READ_UNITS (none)          0x8: force unit u8, torque unit u8
//   0x9  READ_ADC (index u8)        0x9: u16
//   0xC  RESET (none)               no response
//   0xD  SET_BASE_ID (u8)           0xD: ack      0xE SET_BAUD (u8) 0xE: ack
//   0xF  READ_FIRMWARE (none)       0xF: major u8, minor u8, build u16
// The gauge frames interleave: frame 0x0 carries SG0, SG2, SG4 and frame 0x1 SG1, SG3, SG5.
//
// Scaling: wrench_counts = M (6x6, row r = axis r: Fx Fy Fz Tx Ty Tz) * (sg - bias);
//   F = wrench_counts[0..2] / counts_per_force, T = wrench_counts[3..5] / counts_per_torque, in
//   the sensor's unit codes (force: 1 lbf, 2 N, 3 klbf, 4 kN, 5 kgf, 6 gf; torque: 1 lbf-in,
//   2 lbf-ft, 3 N m, 4 N mm, 5 kgf-cm, 6 kN m), which this driver converts to N and N m.
// There is no bias command: tare is host-side, a gauge bias subtracted before the matrix.
//
// Everything here is deterministic, allocation-free, noexcept and O(1); malformed input gives
// an error code, never undefined behaviour.
#pragma once

#include <cstdint>

#include "pliant/drivers/socketcan/can_frame.hpp"

namespace pliant::drivers::socketcan::ati {

inline constexpr std::uint8_t kMaxBaseId = 0x7f;
inline constexpr std::uint8_t kCalibrationCount = 16;

enum class Opcode : std::uint8_t {
  read_gauges = 0x0,    ///< request; also the first gauge response frame
  gauges_second = 0x1,  ///< second gauge response frame
  read_matrix = 0x2,    ///< request; also the first matrix response frame (columns 0, 1)
  matrix_second = 0x3,  ///< columns 2, 3
  matrix_third = 0x4,   ///< columns 4, 5
  read_serial = 0x5,
  set_calibration = 0x6,
  read_counts = 0x7,
  read_units = 0x8,
  read_adc = 0x9,
  reset = 0xc,
  set_base_id = 0xd,
  set_baud = 0xe,
  read_firmware = 0xf,
};

constexpr bool valid_base_id(unsigned base_id) noexcept { return base_id <= kMaxBaseId; }
/// (base_id << 4) | opcode. base_id must be valid (checked by the caller; masked here).
constexpr std::uint32_t can_id(std::uint8_t base_id, Opcode op) noexcept {
  return ((static_cast<std::uint32_t>(base_id) & kMaxBaseId) << 4) | (static_cast<std::uint32_t>(op) & 0xfu);
}

/// A request frame: READ_SG, READ_SERIAL, READ_COUNTS, READ_UNITS, READ_FIRMWARE, RESET carry no
/// payload; READ_MATRIX (axis), SET_CALIBRATION (index), READ_ADC (index), SET_BASE_ID and
/// SET_BAUD carry one byte `arg`.
CanFrame make_request(std::uint8_t base_id, Opcode op, std::uint8_t arg = 0) noexcept;

enum class DecodeError : std::uint8_t {
  none = 0,
  foreign_id,      ///< not a standard data frame, or another base ID
  unknown_opcode,  ///< 0xA, 0xB, or 0xC (RESET has no response)
  wrong_dlc,       ///< a known response with the wrong payload length
};
const char* decode_error_name(DecodeError e) noexcept;

/// One decoded response frame; only the fields of `opcode` are meaningful.
struct Response {
  Opcode opcode = Opcode::read_gauges;
  std::uint16_t status = 0;             ///< read_gauges
  std::int16_t gauges[3] = {0, 0, 0};   ///< read_gauges: SG0 SG2 SG4; gauges_second: SG1 SG3 SG5
  float matrix[2] = {0, 0};             ///< read_matrix / matrix_second / matrix_third: two columns
  char serial[8] = {};                  ///< read_serial: 8 bytes as sent (not NUL-terminated)
  std::uint8_t byte = 0;                ///< set_calibration echo, set_base_id / set_baud ack byte (0 if none)
  std::uint32_t counts_per_force = 0;   ///< read_counts
  std::uint32_t counts_per_torque = 0;  ///< read_counts
  std::uint8_t force_unit = 0;          ///< read_units
  std::uint8_t torque_unit = 0;         ///< read_units
  std::uint16_t adc = 0;                ///< read_adc
  std::uint8_t firmware_major = 0, firmware_minor = 0;  ///< read_firmware
  std::uint16_t firmware_build = 0;                     ///< read_firmware
};

/// Payload lengths of the responses (0: none / not a response).
std::uint8_t response_dlc(Opcode op) noexcept;

/// Decodes a response frame of the sensor at `base_id`. On none, `out` holds it; otherwise
/// `out` is untouched. set_base_id and set_baud acks accept DLC 0 or 1.
DecodeError decode_response(const CanFrame& frame, std::uint8_t base_id, Response& out) noexcept;

/// Raw gauge sample: the status word and SG0..SG5 in gauge order.
struct GaugeSample {
  std::uint16_t status = 0;
  std::int16_t gauges[6] = {0, 0, 0, 0, 0, 0};
};

/// Puts the two gauge frames of one READ_SG back together, in either order.
class GaugeAssembler {
 public:
  enum class Result : std::uint8_t {
    partial,   ///< one half held, waiting for the other
    complete,  ///< both halves: sample() holds the sample; the assembler is empty again
    replaced,  ///< a second copy of a held half: the older one was discarded (counted by the caller)
    ignored,   ///< not a gauge frame
  };
  /// Forgets a held half (a new request, or a response timeout). True if one was held.
  bool reset() noexcept;
  Result add(const Response& r) noexcept;
  bool holding() const noexcept { return have_ != 0; }
  const GaugeSample& sample() const noexcept { return sample_; }

 private:
  GaugeSample pending_;
  GaugeSample sample_;
  std::uint8_t have_ = 0;  ///< bit 0: first frame, bit 1: second frame
};

/// Newtons per force unit code, N m per torque unit code; 0 for an unknown code.
double force_unit_to_newton(std::uint8_t code) noexcept;
double torque_unit_to_newton_metre(std::uint8_t code) noexcept;

/// A calibration as the sensor reports it (or as a user enters it from the calibration file).
struct Calibration {
  float matrix[36] = {};                ///< row-major, row r = axis r (Fx Fy Fz Tx Ty Tz), counts per gauge count
  std::uint32_t counts_per_force = 0;   ///< > 0
  std::uint32_t counts_per_torque = 0;  ///< > 0
  std::uint8_t force_unit = 2;          ///< unit code (2: N)
  std::uint8_t torque_unit = 3;         ///< unit code (3: N m)
};

enum class CalibrationError : std::uint8_t {
  none = 0,
  non_finite_matrix,
  zero_counts,
  unknown_force_unit,
  unknown_torque_unit
};
const char* calibration_error_name(CalibrationError e) noexcept;
CalibrationError check(const Calibration& c) noexcept;

/// A calibration ready to apply: the matrix with each row scaled to N or N m per gauge count.
struct Scaling {
  double matrix[36] = {};  ///< row-major; wrench = matrix * (sg - bias)
};
/// Builds the scaling. On an error `out` is untouched.
CalibrationError make_scaling(const Calibration& c, Scaling& out) noexcept;

/// wrench[6] (N, N m) = scaling.matrix * (gauges - bias). bias in counts (may be fractional).
void gauges_to_wrench(const Scaling& scaling, const std::int16_t gauges[6], const double bias[6],
                      double wrench[6]) noexcept;

/// Status word bits: 1-7, 11, 12 mean the reading must not be trusted (the hal's kFtFaultMask).
inline constexpr std::uint16_t kCriticalStatusMask = 0x18fe;

}  // namespace pliant::drivers::socketcan::ati
