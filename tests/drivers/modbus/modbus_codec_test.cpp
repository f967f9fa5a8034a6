// Pure codecs of the modbus driver against hand-computed register values and manual examples:
// the Modbus CRC, the Robotiq 2F command and status blocks and their scaling, the FT 300
// register scaling and frame/request encoders, and the libmodbus errno mapping.
#include <gtest/gtest.h>
#include <modbus.h>

#include <cerrno>
#include <cmath>
#include <cstdint>
#include <limits>

#include "pliant/drivers/modbus/ft300_codec.hpp"
#include "pliant/drivers/modbus/modbus_crc.hpp"
#include "pliant/drivers/modbus/modbus_link.hpp"
#include "pliant/drivers/modbus/robotiq_2f_codec.hpp"

namespace pliant::drivers::modbus {
namespace {

using hal::HalStatus;
namespace r2f = robotiq2f;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// An independent CRC-16/MODBUS: table-driven, the table built from the unreflected polynomial
// 0x8005 with explicit bit reversal (a different algorithm from the driver's bitwise loop).
std::uint16_t reference_crc(const std::uint8_t* data, std::size_t size) {
  auto reflect = [](std::uint32_t v, int bits) {
    std::uint32_t r = 0;
    for (int i = 0; i < bits; ++i) r |= ((v >> i) & 1u) << (bits - 1 - i);
    return r;
  };
  std::uint16_t table[256];
  for (std::uint32_t b = 0; b < 256; ++b) {
    std::uint32_t crc = reflect(b, 8) << 8;
    for (int i = 0; i < 8; ++i) crc = (crc & 0x8000u) ? ((crc << 1) ^ 0x8005u) : (crc << 1);
    table[b] = static_cast<std::uint16_t>(reflect(crc & 0xffffu, 16));
  }
  std::uint16_t crc = 0xffff;
  for (std::size_t i = 0; i < size; ++i) crc = static_cast<std::uint16_t>((crc >> 8) ^ table[(crc ^ data[i]) & 0xffu]);
  return crc;
}

TEST(ModbusCrc, CheckValueAndManualRequest) {
  const std::uint8_t check[] = {'1', '2', '3', '4', '5', '6', '7', '8', '9'};
  EXPECT_EQ(modbus_crc16(check, sizeof check), 0x4b37);
  // Robotiq manual: status read with FC04 "09 04 07 D0 00 03 B1 CE".
  std::uint8_t request[8] = {0x09, 0x04, 0x07, 0xd0, 0x00, 0x03, 0, 0};
  append_modbus_crc16(request, 6);
  EXPECT_EQ(request[6], 0xb1);
  EXPECT_EQ(request[7], 0xce);
  EXPECT_TRUE(check_modbus_crc16(request, 8));
  request[3] ^= 0x01;
  EXPECT_FALSE(check_modbus_crc16(request, 8));
  EXPECT_FALSE(check_modbus_crc16(request, 2));
  EXPECT_EQ(modbus_crc16(nullptr, 0), 0xffff);
}

TEST(ModbusCrc, AgreesWithIndependentImplementation) {
  std::uint8_t data[300];
  std::uint32_t x = 12345;
  for (std::uint8_t& b : data) {
    x = x * 1103515245u + 12345u;
    b = static_cast<std::uint8_t>(x >> 16);
  }
  for (std::size_t n = 0; n <= sizeof data; n += 7) EXPECT_EQ(modbus_crc16(data, n), reference_crc(data, n)) << n;
}

TEST(Robotiq2fCodec, CommandRegisters) {
  r2f::Command c;
  c.action = r2f::kActionActivate | r2f::kActionGoTo;
  c.position = 0xff;
  c.speed = 0x80;
  c.force = 0x40;
  std::uint16_t regs[3];
  r2f::encode_command(c, regs);
  EXPECT_EQ(regs[0], 0x0900);  // 2F manual: move = {0x0900, 0x00PP, SSFF} (docs/drivers/modbus.md)
  EXPECT_EQ(regs[1], 0x00ff);
  EXPECT_EQ(regs[2], 0x8040);
  r2f::Command activate;
  activate.action = r2f::kActionActivate;
  r2f::encode_command(activate, regs);
  EXPECT_EQ(regs[0], 0x0100);
  EXPECT_EQ(regs[1], 0x0000);
  EXPECT_EQ(regs[2], 0x0000);
  const std::uint16_t back_regs[3] = {0x3900, 0x1234, 0xabcd};
  const r2f::Command back = r2f::decode_command(back_regs);
  EXPECT_EQ(back.action, 0x39);
  EXPECT_EQ(back.position, 0x34);  // byte 2 (high half of register 1) is reserved
  EXPECT_EQ(back.speed, 0xab);
  EXPECT_EQ(back.force, 0xcd);
}

TEST(Robotiq2fCodec, ManualStatusExamples) {
  // "B9 00 00 FF BD 00": object detected while closing, gPR 0xFF, gPO 0xBD.
  const std::uint16_t gripped[3] = {0xb900, 0x00ff, 0xbd00};
  const r2f::Status s = r2f::decode_status(gripped);
  EXPECT_EQ(s.gact, 1);
  EXPECT_EQ(s.ggto, 1);
  EXPECT_EQ(s.gsta, 3);
  EXPECT_EQ(s.gobj, 2);
  EXPECT_EQ(s.gflt, 0);
  EXPECT_EQ(s.kflt, 0);
  EXPECT_EQ(s.position_request, 0xff);
  EXPECT_EQ(s.position, 0xbd);
  EXPECT_EQ(s.current, 0);
  EXPECT_EQ(r2f::status_bits(s), hal::kGripperActivated | hal::kGripperObjectDetected);
  r2f::Scaling sc;  // 2F-85, bytes 0..255
  hal::GripperReading r;
  r2f::to_reading(s, sc, r);
  EXPECT_NEAR(r.width_m, 0.085 * (255.0 - 189.0) / 255.0, 1e-12);
  EXPECT_NEAR(r.target_width_m, 0.0, 1e-12);
  EXPECT_DOUBLE_EQ(r.current_a, 0.0);
  EXPECT_TRUE(std::isnan(r.force_n));

  // "39 00 00 00 BB 10": moving, current 0x10 = 160 mA.
  const std::uint16_t moving[3] = {0x3900, 0x0000, 0xbb10};
  const r2f::Status m = r2f::decode_status(moving);
  EXPECT_EQ(m.gobj, 0);
  EXPECT_EQ(r2f::status_bits(m), hal::kGripperActivated | hal::kGripperMoving);
  r2f::to_reading(m, sc, r);
  EXPECT_NEAR(r.current_a, 0.16, 1e-12);
  EXPECT_NEAR(r.width_m, 0.085 * (255.0 - 0xbb) / 255.0, 1e-12);
}

TEST(Robotiq2fCodec, StatusBitsFollowGotoAndActivation) {
  // gOBJ without gGTO means nothing.
  const std::uint16_t no_goto[3] = {static_cast<std::uint16_t>((0x80 | 0x30 | 0x01) << 8), 0, 0};
  EXPECT_EQ(r2f::status_bits(r2f::decode_status(no_goto)), hal::kGripperActivated);
  // At position.
  const std::uint16_t at[3] = {0xf900, 0, 0};
  EXPECT_EQ(r2f::status_bits(r2f::decode_status(at)), hal::kGripperActivated | hal::kGripperAtTarget);
  // Contact while opening: no hal bit for it, and not at target.
  const std::uint16_t opening[3] = {0x7900, 0, 0};
  EXPECT_EQ(r2f::status_bits(r2f::decode_status(opening)), hal::kGripperActivated);
  // Activating (gSTA 1) with gACT set: not activated yet.
  const std::uint16_t activating[3] = {0x1100, 0, 0};
  EXPECT_EQ(r2f::status_bits(r2f::decode_status(activating)), 0u);
  EXPECT_FALSE(r2f::is_activated(r2f::decode_status(activating)));
}

TEST(Robotiq2fCodec, FaultByteGoesToBits8To15) {
  const std::uint16_t overcurrent[3] = {0x3100, 0x0e00, 0};
  const std::uint32_t bits = r2f::status_bits(r2f::decode_status(overcurrent));
  EXPECT_EQ(hal::gripper_fault_code(bits), hal::kGripperFaultOverCurrent);
  EXPECT_NE(bits & hal::kGripperFaultMask, 0u);
  EXPECT_EQ(bits & ~hal::kGripperFaultMask, hal::kGripperActivated);
  // Controller fault in the high nibble (kFLT) and gFLT 0x05.
  const std::uint16_t both[3] = {0x0000, 0xa500, 0};
  const r2f::Status s = r2f::decode_status(both);
  EXPECT_EQ(s.gflt, 0x05);
  EXPECT_EQ(s.kflt, 0x0a);
  EXPECT_EQ(hal::gripper_fault_code(r2f::status_bits(s)), 0xa5);
  const std::uint16_t none[3] = {0x3100, 0x00ff, 0};
  EXPECT_EQ(r2f::status_bits(r2f::decode_status(none)) & hal::kGripperFaultMask, 0u);
}

TEST(Robotiq2fCodec, StatusRoundTripEveryStatusAndFaultByte) {
  for (unsigned b0 = 0; b0 < 256; ++b0) {
    for (unsigned b2 = 0; b2 < 256; b2 += 5) {
      const std::uint16_t regs[3] = {static_cast<std::uint16_t>(b0 << 8 | 0x5a),
                                     static_cast<std::uint16_t>(b2 << 8 | 0x77), 0x99aa};
      std::uint16_t again[3];
      r2f::encode_status(r2f::decode_status(regs), again);
      // Bits 1, 2 of byte 0 are not defined in the map and are dropped; everything else survives.
      EXPECT_EQ(again[0], regs[0] & 0xf9ff) << b0;
      EXPECT_EQ(again[1], regs[1]);
      EXPECT_EQ(again[2], regs[2]);
    }
  }
}

TEST(Robotiq2fCodec, PositionWidthScaling) {
  r2f::Scaling sc;
  EXPECT_EQ(r2f::width_to_position(0.085, sc), 0);
  EXPECT_EQ(r2f::width_to_position(0.0, sc), 255);
  EXPECT_EQ(r2f::width_to_position(0.04, sc), 135);  // 255 - 120
  EXPECT_EQ(r2f::width_to_position(0.2, sc), 0);     // clamped
  EXPECT_EQ(r2f::width_to_position(-1.0, sc), 255);
  EXPECT_EQ(r2f::width_to_position(kNaN, sc), 0);  // NaN: open_byte
  EXPECT_DOUBLE_EQ(r2f::position_to_width(0, sc), 0.085);
  EXPECT_DOUBLE_EQ(r2f::position_to_width(255, sc), 0.0);
  for (int p = 0; p < 256; ++p) {
    const auto b = static_cast<std::uint8_t>(p);
    EXPECT_EQ(r2f::width_to_position(r2f::position_to_width(b, sc), sc), b);
  }
  // A calibrated 2F-140 whose encoder spans 3..230.
  r2f::Scaling cal;
  cal.stroke_m = 0.140;
  cal.open_byte = 3;
  cal.closed_byte = 230;
  EXPECT_EQ(r2f::width_to_position(0.140, cal), 3);
  EXPECT_EQ(r2f::width_to_position(0.0, cal), 230);
  EXPECT_NEAR(r2f::position_to_width(3, cal), 0.140, 1e-12);
  EXPECT_NEAR(r2f::position_to_width(230, cal), 0.0, 1e-12);
  EXPECT_NEAR(r2f::position_to_width(116, cal), 0.140 * (230.0 - 116.0) / 227.0, 1e-12);
  EXPECT_DOUBLE_EQ(r2f::position_to_width(0, cal), 0.140);  // beyond the open end: clamped
  EXPECT_DOUBLE_EQ(r2f::position_to_width(255, cal), 0.0);  // beyond the closed end: clamped
  // A valid but absurd stroke near DBL_MAX (found by the fuzzer): no overflow in the round trip.
  r2f::Scaling huge;
  huge.stroke_m = 1.0e308;
  huge.open_byte = 127;
  huge.closed_byte = 252;
  for (int p = 127; p <= 252; ++p) {
    const auto b = static_cast<std::uint8_t>(p);
    EXPECT_EQ(r2f::width_to_position(r2f::position_to_width(b, huge), huge), b) << p;
  }
}

TEST(Robotiq2fCodec, SpeedAndForceBytes) {
  r2f::Scaling sc;  // 20..150 mm/s, 20..235 N
  EXPECT_EQ(r2f::speed_to_byte(0.020, sc), 0);
  EXPECT_EQ(r2f::speed_to_byte(0.150, sc), 255);
  EXPECT_EQ(r2f::speed_to_byte(0.0851, sc), 128);  // 127.7
  EXPECT_EQ(r2f::speed_to_byte(1.0, sc), 255);
  EXPECT_EQ(r2f::speed_to_byte(0.0, sc), 0);
  EXPECT_EQ(r2f::speed_to_byte(kNaN, sc), 0);
  EXPECT_NEAR(r2f::byte_to_speed(255, sc), 0.150, 1e-12);
  EXPECT_EQ(r2f::force_to_byte(20, sc), 0);
  EXPECT_EQ(r2f::force_to_byte(235, sc), 255);
  EXPECT_EQ(r2f::force_to_byte(62.15, sc), 50);  // 20 + 50 * 215 / 255 = 62.157 N
  EXPECT_EQ(r2f::force_to_byte(1e9, sc), 255);
  EXPECT_EQ(r2f::force_to_byte(-5, sc), 0);
  EXPECT_EQ(r2f::force_to_byte(kNaN, sc), 0);
  EXPECT_NEAR(r2f::byte_to_force(50, sc), 20 + 50 * 215.0 / 255.0, 1e-12);
}

TEST(Robotiq2fCodec, ScalingValidation) {
  r2f::Scaling ok;
  EXPECT_EQ(r2f::validate(ok), HalStatus::ok);
  r2f::Scaling bad = ok;
  bad.stroke_m = 0;
  EXPECT_EQ(r2f::validate(bad), HalStatus::invalid_argument);
  bad = ok;
  bad.open_byte = bad.closed_byte = 7;
  EXPECT_EQ(r2f::validate(bad), HalStatus::invalid_argument);
  bad = ok;
  bad.max_force_n = bad.min_force_n;
  EXPECT_EQ(r2f::validate(bad), HalStatus::invalid_argument);
  bad = ok;
  bad.min_speed_m_per_s = kNaN;
  EXPECT_EQ(r2f::validate(bad), HalStatus::invalid_argument);
  bad = ok;
  bad.min_force_n = -1;
  EXPECT_EQ(r2f::validate(bad), HalStatus::invalid_argument);
  // Reversed byte direction is allowed (a gripper wired the other way round).
  r2f::Scaling reversed = ok;
  reversed.open_byte = 255;
  reversed.closed_byte = 0;
  EXPECT_EQ(r2f::validate(reversed), HalStatus::ok);
  EXPECT_EQ(r2f::width_to_position(0.085, reversed), 255);
  EXPECT_NEAR(r2f::position_to_width(51, reversed), 0.085 * 51 / 255.0, 1e-12);
}

TEST(Ft300Codec, RegisterScaling) {
  const std::uint16_t regs[6] = {100, 0xff9c, 2000, 1000, 0xfc18, 0x7fff};
  double w[6];
  ft300::registers_to_wrench(regs, w);
  EXPECT_DOUBLE_EQ(w[0], 1.0);
  EXPECT_DOUBLE_EQ(w[1], -1.0);
  EXPECT_DOUBLE_EQ(w[2], 20.0);
  EXPECT_DOUBLE_EQ(w[3], 1.0);
  EXPECT_DOUBLE_EQ(w[4], -1.0);
  EXPECT_DOUBLE_EQ(w[5], 32.767);
  const std::uint16_t extreme[6] = {0x8000, 0xffff, 0, 0x8000, 1, 0xffff};
  ft300::registers_to_wrench(extreme, w);
  EXPECT_DOUBLE_EQ(w[0], -327.68);
  EXPECT_DOUBLE_EQ(w[1], -0.01);
  EXPECT_DOUBLE_EQ(w[3], -32.768);
  EXPECT_DOUBLE_EQ(w[4], 0.001);
  EXPECT_DOUBLE_EQ(w[5], -0.001);
}

TEST(Ft300Codec, WrenchToRegistersRoundsAndSaturates) {
  const double w[6] = {1.234, -0.016, 1e6, kNaN, -1e6, 0.0004};
  std::uint16_t regs[6];
  ft300::wrench_to_registers(w, regs);
  EXPECT_EQ(regs[0], 123);
  EXPECT_EQ(regs[1], 0xfffe);  // -1.6 counts -> -2
  EXPECT_EQ(regs[2], 0x7fff);
  EXPECT_EQ(regs[3], 0);
  EXPECT_EQ(regs[4], 0x8000);
  EXPECT_EQ(regs[5], 0);
}

TEST(Ft300Codec, StreamFrameAndStartRequestBytes) {
  const std::int16_t counts[6] = {100, -100, 1234, -1, 0, 32767};
  std::uint8_t frame[16];
  ft300::encode_stream_frame(counts, frame);
  const std::uint8_t expected[16] = {0x20, 0x4e, 0x64, 0x00, 0x9c, 0xff, 0xd2, 0x04,
                                     0xff, 0xff, 0x00, 0x00, 0xff, 0x7f, 0x59, 0x18};
  for (int i = 0; i < 16; ++i) EXPECT_EQ(frame[i], expected[i]) << i;
  std::uint8_t request[ft300::kStartRequestSize];
  ft300::encode_stream_start_request(9, request);
  const std::uint8_t expected_request[11] = {0x09, 0x10, 0x01, 0x9a, 0x00, 0x01, 0x02, 0x02, 0x00, 0xcd, 0xca};
  for (int i = 0; i < 11; ++i) EXPECT_EQ(request[i], expected_request[i]) << i;
}

TEST(ModbusLinkMapping, ErrnoToStatus) {
  EXPECT_EQ(modbus_errno_status(ETIMEDOUT), HalStatus::timeout);
  EXPECT_EQ(modbus_errno_status(EMBXGTAR), HalStatus::timeout);
  for (int e : {ECONNRESET, ECONNREFUSED, EPIPE, ENOTCONN, EBADF, EIO, ENXIO, ENODEV, ENOENT, EHOSTUNREACH}) {
    EXPECT_EQ(modbus_errno_status(e), HalStatus::disconnected) << e;
  }
  EXPECT_EQ(modbus_errno_status(EMBXILFUN), HalStatus::unsupported);
  for (int e : {EMBBADCRC, EMBBADDATA, EMBBADEXC, EMBUNKEXC, EMBMDATA, EMBBADSLAVE, EMBXILADD, EMBXSBUSY, EINVAL, 0}) {
    EXPECT_EQ(modbus_errno_status(e), HalStatus::io_error) << e;
  }
}

TEST(ModbusLinkMapping, ConfigValidation) {
  ModbusLinkConfig c;
  EXPECT_EQ(validate(c), HalStatus::ok);
  c.parity = 'X';
  EXPECT_EQ(validate(c), HalStatus::invalid_argument);
  c = ModbusLinkConfig{};
  c.response_timeout_s = 0;
  EXPECT_EQ(validate(c), HalStatus::invalid_argument);
  c.response_timeout_s = kNaN;
  EXPECT_EQ(validate(c), HalStatus::invalid_argument);
  c = ModbusLinkConfig{};
  c.slave_id = 248;
  EXPECT_EQ(validate(c), HalStatus::invalid_argument);
  c = ModbusLinkConfig{};
  c.transport = ModbusTransport::tcp;
  EXPECT_EQ(validate(c), HalStatus::ok);
  c.host = "gripper.local";  // no name lookup on the real-time path
  EXPECT_EQ(validate(c), HalStatus::invalid_argument);
  c.host = "127.0.0.1";
  c.port = 0;
  EXPECT_EQ(validate(c), HalStatus::invalid_argument);
}

}  // namespace
}  // namespace pliant::drivers::modbus
