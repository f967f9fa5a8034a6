// libFuzzer target over the modbus driver's register decoders (drivers/modbus/src/
// robotiq_2f_codec.cpp, ft300_codec.cpp): Robotiq 2F status and command blocks as a gripper or a
// corrupted link could deliver them, the scaling with arbitrary (also invalid) parameters, and
// the FT 300 wrench registers.
//
// Input layout (short inputs are zero-padded): 6 bytes status registers, 6 bytes command
// registers, 12 bytes FT 300 registers, then doubles for the scaling (stroke, speeds, forces)
// and a width/speed/force to encode, and two bytes open/closed position.
// Invariants: nothing crashes; decode -> encode keeps every defined bit; the fault code in the
// status bits equals status byte 2; a valid scaling gives widths within [0, stroke] and position
// bytes that map back to within one byte; wrenches equal counts / 100 and / 1000.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>

#include "pliant/drivers/modbus/ft300_codec.hpp"
#include "pliant/drivers/modbus/robotiq_2f_codec.hpp"

namespace {

namespace r2f = pliant::drivers::modbus::robotiq2f;
namespace ft300 = pliant::drivers::modbus::ft300;

void check(bool condition) {
  if (!condition) std::abort();
}

struct Reader {
  const std::uint8_t* data;
  std::size_t size;
  std::size_t at = 0;
  std::uint8_t byte() { return at < size ? data[at++] : 0; }
  std::uint16_t u16() {
    const auto hi = byte();
    return static_cast<std::uint16_t>((hi << 8) | byte());
  }
  double f64() {
    std::uint8_t b[8];
    for (std::uint8_t& x : b) x = byte();
    double d = 0;
    std::memcpy(&d, b, sizeof d);
    return d;
  }
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  Reader in{data, size};
  std::uint16_t status_regs[3], command_regs[3], ft_regs[6];
  for (std::uint16_t& r : status_regs) r = in.u16();
  for (std::uint16_t& r : command_regs) r = in.u16();
  for (std::uint16_t& r : ft_regs) r = in.u16();

  const r2f::Status s = r2f::decode_status(status_regs);
  std::uint16_t again[3];
  r2f::encode_status(s, again);
  check(again[0] == (status_regs[0] & 0xf9ffu) && again[1] == status_regs[1] && again[2] == status_regs[2]);
  const std::uint32_t bits = r2f::status_bits(s);
  check(pliant::hal::gripper_fault_code(bits) == (status_regs[1] >> 8));
  check((bits & ~(pliant::hal::kGripperFaultCodeMask | 0xfu)) == 0);
  const int motion = ((bits & pliant::hal::kGripperMoving) != 0) + ((bits & pliant::hal::kGripperObjectDetected) != 0) +
                     ((bits & pliant::hal::kGripperAtTarget) != 0);
  check(motion <= 1);

  const r2f::Command c = r2f::decode_command(command_regs);
  r2f::encode_command(c, again);
  check(again[0] == (command_regs[0] & 0xff00u) && again[1] == (command_regs[1] & 0x00ffu) &&
        again[2] == command_regs[2]);

  r2f::Scaling sc;
  sc.stroke_m = in.f64();
  sc.min_speed_m_per_s = in.f64();
  sc.max_speed_m_per_s = in.f64();
  sc.min_force_n = in.f64();
  sc.max_force_n = in.f64();
  const double width = in.f64(), speed = in.f64(), force = in.f64();
  sc.open_byte = in.byte();
  sc.closed_byte = in.byte();
  // Whatever the parameters, the conversions must be defined behaviour.
  pliant::hal::GripperReading reading;
  r2f::to_reading(s, sc, reading);
  const std::uint8_t p = r2f::width_to_position(width, sc);
  (void)r2f::speed_to_byte(speed, sc);
  (void)r2f::force_to_byte(force, sc);
  (void)r2f::byte_to_speed(p, sc);
  (void)r2f::byte_to_force(p, sc);
  if (r2f::validate(sc) == pliant::hal::HalStatus::ok) {
    check(reading.width_m >= 0 && reading.width_m <= sc.stroke_m);
    check(reading.target_width_m >= 0 && reading.target_width_m <= sc.stroke_m);
    const int lo = sc.open_byte < sc.closed_byte ? sc.open_byte : sc.closed_byte;
    const int hi = sc.open_byte < sc.closed_byte ? sc.closed_byte : sc.open_byte;
    check(p >= lo && p <= hi);
    const std::uint8_t back = r2f::width_to_position(r2f::position_to_width(p, sc), sc);
    check(std::abs(static_cast<int>(back) - static_cast<int>(p)) <= 1);
  }

  double wrench[6];
  ft300::registers_to_wrench(ft_regs, wrench);
  for (int i = 0; i < 6; ++i) {
    const int counts = ft_regs[i] < 0x8000u ? static_cast<int>(ft_regs[i]) : static_cast<int>(ft_regs[i]) - 0x10000;
    check(wrench[i] == static_cast<double>(counts) / (i < 3 ? 100.0 : 1000.0));
  }
  std::uint16_t round_trip[6];
  ft300::wrench_to_registers(wrench, round_trip);
  for (int i = 0; i < 6; ++i) check(round_trip[i] == ft_regs[i]);
  return 0;
}
