// libFuzzer target over the socketcan driver's pure decoders: ATI NETCANOEM responses and gauge
// reassembly, the calibration scaling, Robotous RFT frame roles, packet reassembly and decoding,
// and SocketCAN error frames.
//
// Input: byte 0 the ATI base ID (low 7 bits), bytes 1..4 the calibration's counts per force and
// per torque (one byte each, two of them) and unit codes; then records of 13 bytes, one frame
// each: id (4 bytes, little-endian, flags included), dlc (any value 0..255: decoders must not
// trust it), 8 data bytes. Every frame goes to every decoder. Invariants are checked with
// abort(): decoded fields agree with the frame, reassembled samples come from decoded halves,
// and every scaled wrench is finite.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>

#include "pliant/drivers/socketcan/ati_netcanoem_protocol.hpp"
#include "pliant/drivers/socketcan/can_error.hpp"
#include "pliant/drivers/socketcan/robotous_rft_protocol.hpp"

namespace sc = pliant::drivers::socketcan;

namespace {

void check(bool condition) {
  if (!condition) std::abort();
}

void check_finite(const double w[6]) {
  for (int k = 0; k < 6; ++k) check(std::isfinite(w[k]));
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 5) return 0;
  const std::uint8_t base = data[0] & sc::ati::kMaxBaseId;
  // A calibration whose matrix is filled from the frames' matrix responses as they come.
  sc::ati::Calibration cal;
  cal.counts_per_force = data[1];
  cal.counts_per_torque = data[2];
  cal.force_unit = data[3];
  cal.torque_unit = data[4];
  int matrix_fill = 0;
  sc::ati::GaugeAssembler gauges;
  sc::rft::PacketAssembler packets;
  const sc::rft::Ids ids{static_cast<std::uint16_t>(data[1] | ((data[2] & 7u) << 8)),
                         static_cast<std::uint16_t>(data[3] | ((data[4] & 7u) << 8)), 0x7ff};
  const bool ids_valid = sc::rft::valid(ids);
  const double no_bias[6] = {0, 0, 0, 0, 0, 0};

  for (std::size_t at = 5; at + 13 <= size; at += 13) {
    sc::CanFrame f;
    std::uint32_t id = 0;
    for (int i = 0; i < 4; ++i) id |= static_cast<std::uint32_t>(data[at + static_cast<std::size_t>(i)]) << (8 * i);
    f.id = id;
    f.dlc = data[at + 4];
    std::memcpy(f.data, data + at + 5, 8);

    // ATI.
    sc::ati::Response r;
    const sc::ati::DecodeError e = sc::ati::decode_response(f, base, r);
    if (e == sc::ati::DecodeError::none) {
      check(sc::is_standard_data_frame(f));
      check((f.id >> 4) == base);
      check(static_cast<unsigned>(r.opcode) == (f.id & 0xfu));
      check(f.dlc <= 8);
      if (r.opcode == sc::ati::Opcode::read_gauges) check(r.status == sc::load_be_u16(f.data));
      if (r.opcode == sc::ati::Opcode::read_matrix || r.opcode == sc::ati::Opcode::matrix_second ||
          r.opcode == sc::ati::Opcode::matrix_third) {
        for (int i = 0; i < 2; ++i) cal.matrix[(matrix_fill++) % 36] = r.matrix[i];
      }
      const sc::ati::GaugeAssembler::Result a = gauges.add(r);
      if (a == sc::ati::GaugeAssembler::Result::complete) {
        check(!gauges.holding());
        sc::ati::Scaling s;
        if (sc::ati::make_scaling(cal, s) == sc::ati::CalibrationError::none) {
          double w[6];
          sc::ati::gauges_to_wrench(s, gauges.sample().gauges, no_bias, w);
          check_finite(w);
        }
      }
    } else {
      check(e == sc::ati::DecodeError::foreign_id || e == sc::ati::DecodeError::unknown_opcode ||
            e == sc::ati::DecodeError::wrong_dlc);
      (void)sc::ati::decode_error_name(e);
    }

    // Robotous.
    if (ids_valid) {
      const sc::rft::FrameRole role = sc::rft::classify(f, ids);
      if (role == sc::rft::FrameRole::first || role == sc::rft::FrameRole::second) check(f.dlc == 8);
      if (packets.add(role, f) == sc::rft::PacketAssembler::Result::complete) {
        sc::rft::FtPacket p;
        if (sc::rft::decode_ft_packet(packets.packet(), p) == sc::rft::PacketError::none) {
          check(p.command == 10 || p.command == 11);
          double w[6];
          sc::rft::raw_to_wrench(p.raw, 50.0, 2000.0, w);
          check_finite(w);
          for (int k = 0; k < 3; ++k) check(std::fabs(w[k]) <= 32768.0 / 50.0);
        }
      }
    }

    // SocketCAN error frames.
    sc::CanErrorReport report;
    const bool is_error = sc::decode_can_error(f, report);
    check(is_error == sc::is_error_frame(f));
    if (is_error) {
      check((report.classes & ~sc::kCanErrClassMask) == 0);
      if ((report.classes & sc::kCanErrController) == 0) check(report.controller == 0);
      (void)report.bus_off();
      (void)report.recovered();
    }
  }
  return 0;
}
