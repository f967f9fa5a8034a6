// The pure parts of the socketcan driver against frames written out by hand: the ATI NETCANOEM
// ID arithmetic, big-endian fields, gauge reassembly, calibration math and unit conversion; the
// Robotous RFT packet split and scaling; SocketCAN error frames.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>

#include "pliant/drivers/socketcan/ati_netcanoem_protocol.hpp"
#include "pliant/drivers/socketcan/can_error.hpp"
#include "pliant/drivers/socketcan/can_link.hpp"
#include "pliant/drivers/socketcan/robotous_rft_protocol.hpp"
#include "socketcan_fixture.hpp"

namespace pliant::drivers::socketcan {
namespace {

CanFrame frame(std::uint32_t id, std::initializer_list<int> bytes) {
  CanFrame f;
  f.id = id;
  f.dlc = static_cast<std::uint8_t>(bytes.size());
  int i = 0;
  for (int b : bytes) f.data[i++] = static_cast<std::uint8_t>(b);
  return f;
}

// --- ATI NETCANOEM -------------------------------------------------------------------------

TEST(SocketCanAtiProtocol, IdIsBaseShiftedByFourOrOpcode) {
  // (base << 4) | opcode; an old driver used << 7, which would give 0x1000 here.
  EXPECT_EQ(ati::can_id(0x20, ati::Opcode::read_gauges), 0x200u);
  EXPECT_EQ(ati::can_id(0x20, ati::Opcode::gauges_second), 0x201u);
  EXPECT_EQ(ati::can_id(0x7f, ati::Opcode::read_firmware), 0x7ffu);
  EXPECT_EQ(ati::can_id(0x00, ati::Opcode::set_calibration), 0x006u);
  EXPECT_EQ(ati::can_id(0x01, ati::Opcode::read_matrix), 0x012u);
  EXPECT_TRUE(ati::valid_base_id(0x7f));
  EXPECT_FALSE(ati::valid_base_id(0x80));
}

TEST(SocketCanAtiProtocol, RequestsCarryTheirArgumentOnly) {
  const CanFrame sg = ati::make_request(0x20, ati::Opcode::read_gauges, 9);
  EXPECT_EQ(sg.id, 0x200u);
  EXPECT_EQ(sg.dlc, 0);
  const CanFrame m = ati::make_request(0x20, ati::Opcode::read_matrix, 4);
  EXPECT_EQ(m.id, 0x202u);
  ASSERT_EQ(m.dlc, 1);
  EXPECT_EQ(m.data[0], 4);
  const CanFrame cal = ati::make_request(0x15, ati::Opcode::set_calibration, 3);
  EXPECT_EQ(cal.id, 0x156u);
  EXPECT_EQ(cal.dlc, 1);
  EXPECT_EQ(ati::make_request(0x15, ati::Opcode::read_counts).dlc, 0);
}

TEST(SocketCanAtiProtocol, GaugeFramesAreBigEndianAndInterleaved) {
  // Frame 0x0: status 0x8041, SG0 = 100 (0x0064), SG2 = 300 (0x012c), SG4 = -400 (0xfe70).
  const CanFrame f0 = frame(0x200, {0x80, 0x41, 0x00, 0x64, 0x01, 0x2c, 0xfe, 0x70});
  // Frame 0x1: SG1 = -200 (0xff38), SG3 = 50 (0x0032), SG5 = 20 (0x0014).
  const CanFrame f1 = frame(0x201, {0xff, 0x38, 0x00, 0x32, 0x00, 0x14});
  ati::Response r0, r1;
  ASSERT_EQ(ati::decode_response(f0, 0x20, r0), ati::DecodeError::none);
  ASSERT_EQ(ati::decode_response(f1, 0x20, r1), ati::DecodeError::none);
  EXPECT_EQ(r0.status, 0x8041);
  EXPECT_EQ(r0.gauges[0], 100);
  EXPECT_EQ(r0.gauges[1], 300);
  EXPECT_EQ(r0.gauges[2], -400);
  EXPECT_EQ(r1.gauges[0], -200);
  ati::GaugeAssembler a;
  EXPECT_EQ(a.add(r0), ati::GaugeAssembler::Result::partial);
  ASSERT_EQ(a.add(r1), ati::GaugeAssembler::Result::complete);
  EXPECT_EQ(a.sample().status, 0x8041);
  const std::int16_t expected[6] = {100, -200, 300, 50, -400, 20};  // SG0..SG5 in order
  for (int k = 0; k < 6; ++k) EXPECT_EQ(a.sample().gauges[k], expected[k]) << "SG" << k;
  EXPECT_FALSE(a.holding());
}

TEST(SocketCanAtiProtocol, ReassemblyInEitherOrderAndWithLostOrRepeatedHalves) {
  ati::Response first, second;
  first.opcode = ati::Opcode::read_gauges;
  first.gauges[0] = 1;
  first.gauges[1] = 3;
  first.gauges[2] = 5;
  second.opcode = ati::Opcode::gauges_second;
  second.gauges[0] = 2;
  second.gauges[1] = 4;
  second.gauges[2] = 6;
  ati::GaugeAssembler a;
  // Second half first.
  EXPECT_EQ(a.add(second), ati::GaugeAssembler::Result::partial);
  ASSERT_EQ(a.add(first), ati::GaugeAssembler::Result::complete);
  for (int k = 0; k < 6; ++k) EXPECT_EQ(a.sample().gauges[k], k + 1);
  // A repeated first half replaces the held one.
  EXPECT_EQ(a.add(first), ati::GaugeAssembler::Result::partial);
  first.gauges[0] = 11;
  EXPECT_EQ(a.add(first), ati::GaugeAssembler::Result::replaced);
  ASSERT_EQ(a.add(second), ati::GaugeAssembler::Result::complete);
  EXPECT_EQ(a.sample().gauges[0], 11);
  // A missing half: reset() reports the orphan, and the next pair is clean.
  EXPECT_EQ(a.add(first), ati::GaugeAssembler::Result::partial);
  EXPECT_TRUE(a.reset());
  EXPECT_FALSE(a.reset());
  EXPECT_EQ(a.add(second), ati::GaugeAssembler::Result::partial);
  // Other responses are not gauge frames.
  ati::Response other;
  other.opcode = ati::Opcode::read_counts;
  EXPECT_EQ(a.add(other), ati::GaugeAssembler::Result::ignored);
}

TEST(SocketCanAtiProtocol, MatrixCountsUnitsSerialFirmwareDecode) {
  ati::Response r;
  // 2.0f = 0x40000000, -1.5f = 0xbfc00000.
  ASSERT_EQ(ati::decode_response(frame(0x203, {0x40, 0, 0, 0, 0xbf, 0xc0, 0, 0}), 0x20, r), ati::DecodeError::none);
  EXPECT_EQ(r.opcode, ati::Opcode::matrix_second);
  EXPECT_EQ(r.matrix[0], 2.0f);
  EXPECT_EQ(r.matrix[1], -1.5f);
  // counts per force 1000000 = 0x000f4240, per torque 2000 = 0x000007d0.
  ASSERT_EQ(ati::decode_response(frame(0x207, {0x00, 0x0f, 0x42, 0x40, 0, 0, 0x07, 0xd0}), 0x20, r),
            ati::DecodeError::none);
  EXPECT_EQ(r.counts_per_force, 1000000u);
  EXPECT_EQ(r.counts_per_torque, 2000u);
  ASSERT_EQ(ati::decode_response(frame(0x208, {1, 2}), 0x20, r), ati::DecodeError::none);
  EXPECT_EQ(r.force_unit, 1);
  EXPECT_EQ(r.torque_unit, 2);
  ASSERT_EQ(ati::decode_response(frame(0x205, {'F', 'T', '1', '2', '3', '4', '5', '6'}), 0x20, r),
            ati::DecodeError::none);
  EXPECT_EQ(std::memcmp(r.serial, "FT123456", 8), 0);
  ASSERT_EQ(ati::decode_response(frame(0x20f, {3, 7, 0x01, 0x02}), 0x20, r), ati::DecodeError::none);
  EXPECT_EQ(r.firmware_major, 3);
  EXPECT_EQ(r.firmware_minor, 7);
  EXPECT_EQ(r.firmware_build, 0x0102);
  ASSERT_EQ(ati::decode_response(frame(0x206, {5}), 0x20, r), ati::DecodeError::none);
  EXPECT_EQ(r.byte, 5);
  ASSERT_EQ(ati::decode_response(frame(0x209, {0x12, 0x34}), 0x20, r), ati::DecodeError::none);
  EXPECT_EQ(r.adc, 0x1234);
  ASSERT_EQ(ati::decode_response(frame(0x20d, {}), 0x20, r), ati::DecodeError::none);  // ack without payload
  ASSERT_EQ(ati::decode_response(frame(0x20e, {3}), 0x20, r), ati::DecodeError::none);
}

TEST(SocketCanAtiProtocol, MalformedFramesAreRejectedWithTheirReason) {
  ati::Response r;
  r.status = 0xabcd;
  EXPECT_EQ(ati::decode_response(frame(0x300, {0, 0, 0, 0, 0, 0, 0, 0}), 0x20, r), ati::DecodeError::foreign_id);
  EXPECT_EQ(ati::decode_response(frame(0x200 | kCanEffFlag, {0, 0, 0, 0, 0, 0, 0, 0}), 0x20, r),
            ati::DecodeError::foreign_id);
  EXPECT_EQ(ati::decode_response(frame(0x200 | kCanRtrFlag, {}), 0x20, r), ati::DecodeError::foreign_id);
  EXPECT_EQ(ati::decode_response(frame(0x200 | kCanErrFlag, {0, 0, 0, 0, 0, 0, 0, 0}), 0x20, r),
            ati::DecodeError::foreign_id);
  EXPECT_EQ(ati::decode_response(frame(0x20a, {0}), 0x20, r), ati::DecodeError::unknown_opcode);
  EXPECT_EQ(ati::decode_response(frame(0x20b, {0}), 0x20, r), ati::DecodeError::unknown_opcode);
  EXPECT_EQ(ati::decode_response(frame(0x20c, {}), 0x20, r), ati::DecodeError::unknown_opcode);
  EXPECT_EQ(ati::decode_response(frame(0x200, {0, 0, 0, 0, 0, 0, 0}), 0x20, r), ati::DecodeError::wrong_dlc);
  EXPECT_EQ(ati::decode_response(frame(0x200, {}), 0x20, r), ati::DecodeError::wrong_dlc);  // our own READ_SG request
  EXPECT_EQ(ati::decode_response(frame(0x201, {0, 0, 0, 0, 0, 0, 0, 0}), 0x20, r), ati::DecodeError::wrong_dlc);
  EXPECT_EQ(ati::decode_response(frame(0x208, {2}), 0x20, r), ati::DecodeError::wrong_dlc);
  EXPECT_EQ(ati::decode_response(frame(0x20d, {1, 2}), 0x20, r), ati::DecodeError::wrong_dlc);
  EXPECT_EQ(r.status, 0xabcd);  // untouched
  EXPECT_STREQ(ati::decode_error_name(ati::DecodeError::wrong_dlc), "wrong_dlc");
}

TEST(SocketCanAtiCalibration, HandExample) {
  // M has Fx = 2 SG0 + 0.5 SG5, Fy = SG1, Fz = -1.5 SG2, Tx = 4 SG3, Ty = SG4, Tz = -2 SG5;
  // 1000 counts per N, 2000 counts per N m. With SG = (100, -200, 300, 50, -400, 20):
  //   Fx = (200 + 10) / 1000 = 0.21 N     Tx = 200 / 2000 = 0.1 N m
  //   Fy = -200 / 1000 = -0.2 N           Ty = -400 / 2000 = -0.2 N m
  //   Fz = -450 / 1000 = -0.45 N          Tz = -40 / 2000 = -0.02 N m
  ati::Scaling s;
  ASSERT_EQ(ati::make_scaling(test::hand_calibration(), s), ati::CalibrationError::none);
  const double no_bias[6] = {0, 0, 0, 0, 0, 0};
  double w[6];
  ati::gauges_to_wrench(s, test::kHandGauges, no_bias, w);
  const double expected[6] = {0.21, -0.2, -0.45, 0.1, -0.2, -0.02};
  for (int k = 0; k < 6; ++k) EXPECT_NEAR(w[k], expected[k], 1e-12) << "axis " << k;
  // A bias of (100, 0, 0, 0, 0, 20) leaves only Fy, Fz, Tx, Ty.
  const double bias[6] = {100, 0, 0, 0, 0, 20};
  ati::gauges_to_wrench(s, test::kHandGauges, bias, w);
  EXPECT_NEAR(w[0], 0.0, 1e-12);
  EXPECT_NEAR(w[1], -0.2, 1e-12);
  EXPECT_NEAR(w[5], 0.0, 1e-12);
}

TEST(SocketCanAtiCalibration, UnitCodesConvertToSi) {
  EXPECT_DOUBLE_EQ(ati::force_unit_to_newton(1), 4.4482216152605);  // lbf
  EXPECT_DOUBLE_EQ(ati::force_unit_to_newton(2), 1.0);
  EXPECT_NEAR(ati::force_unit_to_newton(3), 4448.2216152605, 1e-11);  // klbf
  EXPECT_DOUBLE_EQ(ati::force_unit_to_newton(4), 1000.0);
  EXPECT_DOUBLE_EQ(ati::force_unit_to_newton(5), 9.80665);
  EXPECT_NEAR(ati::force_unit_to_newton(6), 0.00980665, 1e-17);
  EXPECT_EQ(ati::force_unit_to_newton(0), 0.0);
  EXPECT_EQ(ati::force_unit_to_newton(7), 0.0);
  EXPECT_NEAR(ati::torque_unit_to_newton_metre(1), 0.1129848290276167, 1e-15);  // lbf in
  EXPECT_NEAR(ati::torque_unit_to_newton_metre(2), 1.3558179483314004, 1e-14);  // lbf ft
  EXPECT_DOUBLE_EQ(ati::torque_unit_to_newton_metre(3), 1.0);
  EXPECT_DOUBLE_EQ(ati::torque_unit_to_newton_metre(4), 0.001);
  EXPECT_DOUBLE_EQ(ati::torque_unit_to_newton_metre(5), 0.0980665);
  EXPECT_DOUBLE_EQ(ati::torque_unit_to_newton_metre(6), 1000.0);
  EXPECT_EQ(ati::torque_unit_to_newton_metre(9), 0.0);
  // One gauge count through an identity matrix at 1 count per lbf reads 4.448... N.
  ati::Calibration c = test::hand_calibration();
  for (float& v : c.matrix) v = 0;
  for (int k = 0; k < 6; ++k) c.matrix[7 * k] = 1.0f;
  c.counts_per_force = 1;
  c.counts_per_torque = 1;
  c.force_unit = 1;
  c.torque_unit = 1;
  ati::Scaling s;
  ASSERT_EQ(ati::make_scaling(c, s), ati::CalibrationError::none);
  const std::int16_t one[6] = {1, 1, 1, 1, 1, 1};
  const double no_bias[6] = {0, 0, 0, 0, 0, 0};
  double w[6];
  ati::gauges_to_wrench(s, one, no_bias, w);
  EXPECT_DOUBLE_EQ(w[0], 4.4482216152605);
  EXPECT_NEAR(w[5], 0.1129848290276167, 1e-15);
}

TEST(SocketCanAtiCalibration, BadCalibrationsAreNamed) {
  ati::Scaling s;
  ati::Calibration c = test::hand_calibration();
  c.counts_per_torque = 0;
  EXPECT_EQ(ati::make_scaling(c, s), ati::CalibrationError::zero_counts);
  c = test::hand_calibration();
  c.matrix[17] = std::numeric_limits<float>::quiet_NaN();
  EXPECT_EQ(ati::make_scaling(c, s), ati::CalibrationError::non_finite_matrix);
  c = test::hand_calibration();
  c.force_unit = 0;
  EXPECT_EQ(ati::check(c), ati::CalibrationError::unknown_force_unit);
  c = test::hand_calibration();
  c.torque_unit = 7;
  EXPECT_EQ(ati::check(c), ati::CalibrationError::unknown_torque_unit);
  EXPECT_STREQ(ati::calibration_error_name(ati::CalibrationError::zero_counts), "zero_counts");
}

TEST(SocketCanAtiProtocol, FloatFieldsRoundTripBitExactly) {
  std::uint8_t b[4];
  store_be_f32(b, -1.5f);
  EXPECT_EQ(b[0], 0xbf);
  EXPECT_EQ(b[1], 0xc0);
  EXPECT_EQ(b[2], 0x00);
  EXPECT_EQ(b[3], 0x00);
  EXPECT_EQ(load_be_f32(b), -1.5f);
  EXPECT_EQ(load_be_i16(b), static_cast<std::int16_t>(-16448));  // 0xbfc0
  EXPECT_EQ(load_be_u32(b), 0xbfc00000u);
}

// --- Robotous RFT ----------------------------------------------------------------------------

TEST(SocketCanRftProtocol, HandPacketDecodesAndScales) {
  // Fx = 100 -> 2 N, Fy = -50 -> -1 N, Fz = 2500 -> 50 N (divider 50);
  // Tx = -2000 (0xf830) -> -1 N m, Ty = 1000 -> 0.5 N m, Tz = 1 -> 0.0005 N m (divider 2000).
  // Tx straddles the frames: 0xf8 ends frame 1, 0x30 starts frame 2. Overload byte 0x24.
  const rft::Ids ids;  // 0x64, 0x01, 0x02
  const CanFrame f1 = frame(0x01, {0x0b, 0x00, 0x64, 0xff, 0xce, 0x09, 0xc4, 0xf8});
  const CanFrame f2 = frame(0x02, {0x30, 0x03, 0xe8, 0x00, 0x01, 0x24, 0x00, 0x00});
  ASSERT_EQ(rft::classify(f1, ids), rft::FrameRole::first);
  ASSERT_EQ(rft::classify(f2, ids), rft::FrameRole::second);
  rft::PacketAssembler a;
  EXPECT_EQ(a.add(rft::FrameRole::first, f1), rft::PacketAssembler::Result::partial);
  ASSERT_EQ(a.add(rft::FrameRole::second, f2), rft::PacketAssembler::Result::complete);
  rft::FtPacket p;
  ASSERT_EQ(rft::decode_ft_packet(a.packet(), p), rft::PacketError::none);
  EXPECT_EQ(p.command, 11);
  const std::int16_t raw[6] = {100, -50, 2500, -2000, 1000, 1};
  for (int k = 0; k < 6; ++k) EXPECT_EQ(p.raw[k], raw[k]) << k;
  EXPECT_EQ(p.overload, 0x24);
  double w[6];
  rft::raw_to_wrench(p.raw, 50.0, 2000.0, w);
  const double expected[6] = {2.0, -1.0, 50.0, -1.0, 0.5, 0.0005};
  for (int k = 0; k < 6; ++k) EXPECT_DOUBLE_EQ(w[k], expected[k]) << k;
  // The emulator's encoder produces exactly these frames.
  std::uint8_t packet[rft::kPacketSize];
  rft::encode_ft_packet(11, raw, 0x24, packet);
  CanFrame e1, e2;
  rft::split_packet(ids, packet, e1, e2);
  EXPECT_EQ(std::memcmp(e1.data, f1.data, 8), 0);
  EXPECT_EQ(std::memcmp(e2.data, f2.data, 8), 0);
  EXPECT_EQ(e1.id, 0x01u);
  EXPECT_EQ(e2.id, 0x02u);
}

TEST(SocketCanRftProtocol, CommandsAreEightBytes) {
  rft::Ids ids;
  ids.command = 0xf0;
  ids.response_1 = 0xf1;
  ids.response_2 = 0xf2;
  const CanFrame c = rft::make_command(ids, rft::kCmdSetBias, 1);
  EXPECT_EQ(c.id, 0xf0u);
  EXPECT_EQ(c.dlc, 8);
  EXPECT_EQ(c.data[0], 17);
  EXPECT_EQ(c.data[1], 1);
  for (int i = 2; i < 8; ++i) EXPECT_EQ(c.data[i], 0);
  EXPECT_TRUE(rft::valid(ids));
  ids.response_2 = 0xf1;
  EXPECT_FALSE(rft::valid(ids));
  ids.response_2 = 0x800;
  EXPECT_FALSE(rft::valid(ids));
}

TEST(SocketCanRftProtocol, MalformedAndUnpairedFrames) {
  const rft::Ids ids;
  EXPECT_EQ(rft::classify(frame(0x03, {0, 0, 0, 0, 0, 0, 0, 0}), ids), rft::FrameRole::foreign);
  EXPECT_EQ(rft::classify(frame(0x01 | kCanEffFlag, {0, 0, 0, 0, 0, 0, 0, 0}), ids), rft::FrameRole::foreign);
  EXPECT_EQ(rft::classify(frame(0x01 | kCanRtrFlag, {}), ids), rft::FrameRole::foreign);
  EXPECT_EQ(rft::classify(frame(0x01, {0, 0, 0, 0, 0, 0, 0}), ids), rft::FrameRole::wrong_dlc);
  EXPECT_EQ(rft::classify(frame(0x64, {0, 0, 0, 0, 0, 0, 0, 0}), ids), rft::FrameRole::foreign);  // a command
  rft::PacketAssembler a;
  const CanFrame f = frame(0x01, {0x0b, 0, 0, 0, 0, 0, 0, 0});
  EXPECT_EQ(a.add(rft::FrameRole::second, f), rft::PacketAssembler::Result::orphan_second);
  EXPECT_EQ(a.add(rft::FrameRole::first, f), rft::PacketAssembler::Result::partial);
  EXPECT_EQ(a.add(rft::FrameRole::first, f), rft::PacketAssembler::Result::replaced_first);
  EXPECT_EQ(a.add(rft::FrameRole::foreign, f), rft::PacketAssembler::Result::ignored);
  EXPECT_TRUE(a.reset());
  // A complete packet that is not F/T data (the answer to "set output rate").
  std::uint8_t packet[rft::kPacketSize] = {15, 1};
  rft::FtPacket p;
  p.command = 99;
  EXPECT_EQ(rft::decode_ft_packet(packet, p), rft::PacketError::not_ft);
  EXPECT_EQ(p.command, 99);  // untouched
}

// --- SocketCAN error frames and receive stamps ----------------------------------------------

TEST(SocketCanErrorFrame, ClassesAndDetailsDecode) {
  // Controller problem (TX passive) with valid counters: TX 130, RX 5.
  const CanFrame f = frame(kCanErrFlag | kCanErrController | kCanErrCounters, {0, 0x20, 0, 0, 0, 0, 130, 5});
  CanErrorReport r;
  ASSERT_TRUE(decode_can_error(f, r));
  EXPECT_EQ(r.classes, kCanErrController | kCanErrCounters);
  EXPECT_EQ(r.controller, kCanCtrlTxPassive);
  EXPECT_EQ(r.tx_errors, 130);
  EXPECT_EQ(r.rx_errors, 5);
  EXPECT_FALSE(r.bus_off());
  EXPECT_FALSE(r.recovered());
  ASSERT_TRUE(decode_can_error(make_can_error_frame(kCanErrBusOff, nullptr), r));
  EXPECT_TRUE(r.bus_off());
  ASSERT_TRUE(decode_can_error(make_can_error_frame(kCanErrRestarted, nullptr), r));
  EXPECT_TRUE(r.recovered());
  const std::uint8_t active[8] = {0, kCanCtrlActive, 0, 0, 0, 0, 0, 0};
  ASSERT_TRUE(decode_can_error(make_can_error_frame(kCanErrController, active), r));
  EXPECT_TRUE(r.recovered());
  const std::uint8_t overflow[8] = {0, kCanCtrlRxOverflow, 0, 0, 0, 0, 0, 0};
  ASSERT_TRUE(decode_can_error(make_can_error_frame(kCanErrController, overflow), r));
  EXPECT_TRUE(r.rx_overflow());
  // A data frame is not an error frame; a short error frame still gives its classes.
  EXPECT_FALSE(decode_can_error(frame(0x123, {1}), r));
  CanFrame shortf = frame(kCanErrFlag | kCanErrCounters, {1, 2});
  shortf.data[6] = 77;  // beyond dlc: must not be read
  ASSERT_TRUE(decode_can_error(shortf, r));
  EXPECT_EQ(r.tx_errors, 0);
  EXPECT_EQ(kDefaultCanErrorMask & kCanErrBusError, 0u);
  EXPECT_NE(kDefaultCanErrorMask & kCanErrBusOff, 0u);
}

TEST(SocketCanLink, ReceiveStampIsNowMinusTheFramesAge) {
  bool trusted = false;
  // Received 2.5 ms ago (realtime), device clock at 100 s: captured at 99.9975 s.
  EXPECT_DOUBLE_EQ(receive_stamp_s(100.0, 5'000'000'000, 4'997'500'000, 1.0, trusted), 100.0 - 0.0025);
  EXPECT_TRUE(trusted);
  // Unknown, future (realtime clock stepped back) and too old (stepped forward) stamps: now.
  EXPECT_EQ(receive_stamp_s(100.0, 5'000'000'000, -1, 1.0, trusted), 100.0);
  EXPECT_FALSE(trusted);
  EXPECT_EQ(receive_stamp_s(100.0, 5'000'000'000, 5'000'000'001, 1.0, trusted), 100.0);
  EXPECT_FALSE(trusted);
  EXPECT_EQ(receive_stamp_s(100.0, 5'000'000'000, 3'000'000'000, 1.0, trusted), 100.0);
  EXPECT_FALSE(trusted);
}

TEST(SocketCanLink, ConfigValidation) {
  CanLinkConfig c;
  EXPECT_EQ(validate(c), hal::HalStatus::ok);
  c.max_frames_per_read = 0;
  EXPECT_EQ(validate(c), hal::HalStatus::invalid_argument);
  c = CanLinkConfig{};
  c.reconnect_interval_s = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(validate(c), hal::HalStatus::invalid_argument);
  c = CanLinkConfig{};
  c.samples_after_restart = -1;
  EXPECT_EQ(validate(c), hal::HalStatus::invalid_argument);
  c = CanLinkConfig{};
  c.max_receive_age_s = 0;
  EXPECT_EQ(validate(c), hal::HalStatus::invalid_argument);
}

}  // namespace
}  // namespace pliant::drivers::socketcan
