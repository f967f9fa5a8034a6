#include "pliant/drivers/socketcan/emulator/ati_netcanoem_emulator.hpp"

#include <cstring>

#include "pliant/drivers/socketcan/can_error.hpp"

namespace pliant::drivers::socketcan {

AtiNetCanEmulator::AtiNetCanEmulator(CanTransport& link, const AtiEmulatorConfig& config) noexcept
    : link_(&link), config_(config), base_id_(static_cast<std::uint8_t>(config.base_id & ati::kMaxBaseId)) {}

void AtiNetCanEmulator::set_gauges(const std::int16_t gauges[6]) noexcept {
  std::memcpy(gauges_, gauges, sizeof gauges_);
}

CanIo AtiNetCanEmulator::send_raw(const CanFrame& frame) noexcept {
  const CanIo io = link_->send(frame);
  if (io == CanIo::ok) {
    ++counters_.frames_sent;
  } else {
    ++counters_.send_failures;
  }
  return io;
}

CanIo AtiNetCanEmulator::send_error(std::uint32_t classes, const std::uint8_t* data8) noexcept {
  return send_raw(make_can_error_frame(classes, data8));
}

void AtiNetCanEmulator::send(ati::Opcode op, const std::uint8_t* payload, std::uint8_t dlc) noexcept {
  (void)send_raw(make_standard_frame(ati::can_id(base_id_, op), payload, dlc));
}

int AtiNetCanEmulator::service(int max_requests) noexcept {
  int n = 0;
  while (n < max_requests && link_->is_open()) {
    CanFrame f;
    CanRxInfo info;
    const CanIo io = link_->receive(f, info);
    if (io == CanIo::empty || io == CanIo::disconnected || io == CanIo::io_error) break;
    ++n;
    if (io != CanIo::ok || !is_standard_data_frame(f) || (f.id >> 4) != base_id_) {
      ++counters_.ignored_frames;
      continue;
    }
    ++counters_.requests;
    if (!faults_.mute) answer(f);
  }
  return n;
}

void AtiNetCanEmulator::answer_gauges() noexcept {
  std::uint8_t first[8];
  store_be_u16(first, status_);
  store_be_i16(first + 2, gauges_[0]);
  store_be_i16(first + 4, gauges_[2]);
  store_be_i16(first + 6, gauges_[4]);
  std::uint8_t second[6];
  store_be_i16(second, gauges_[1]);
  store_be_i16(second + 2, gauges_[3]);
  store_be_i16(second + 4, gauges_[5]);
  bool send_first = true, send_second = true;
  if (faults_.drop_first_halves > 0) {
    --faults_.drop_first_halves;
    send_first = false;
  }
  if (faults_.drop_second_halves > 0) {
    --faults_.drop_second_halves;
    send_second = false;
  }
  int first_copies = send_first ? 1 : 0;
  if (send_first && faults_.duplicate_first_halves > 0) {
    --faults_.duplicate_first_halves;
    first_copies = 2;
  }
  std::uint8_t second_dlc = 6;
  if (faults_.wrong_dlc_answers > 0) {
    --faults_.wrong_dlc_answers;
    second_dlc = 5;
  }
  if (faults_.swap_halves && send_second) send(ati::Opcode::gauges_second, second, second_dlc);
  for (int i = 0; i < first_copies; ++i) send(ati::Opcode::read_gauges, first, 8);
  if (!faults_.swap_halves && send_second) send(ati::Opcode::gauges_second, second, second_dlc);
}

void AtiNetCanEmulator::answer(const CanFrame& request) noexcept {
  const auto op = static_cast<ati::Opcode>(request.id & 0xfu);
  std::uint8_t p[8] = {0, 0, 0, 0, 0, 0, 0, 0};
  switch (op) {
    case ati::Opcode::read_gauges:
      ++counters_.gauge_requests;
      answer_gauges();
      return;
    case ati::Opcode::read_matrix: {
      if (request.dlc < 1 || request.data[0] > 5) break;
      ++counters_.matrix_requests;
      const float* row = config_.calibration.matrix + 6 * request.data[0];
      const ati::Opcode parts[3] = {ati::Opcode::read_matrix, ati::Opcode::matrix_second, ati::Opcode::matrix_third};
      for (int k = 0; k < 3; ++k) {
        store_be_f32(p, row[2 * k]);
        store_be_f32(p + 4, row[2 * k + 1]);
        send(parts[k], p, 8);
      }
      return;
    }
    case ati::Opcode::read_serial:
      std::memcpy(p, config_.serial, 8);
      send(op, p, 8);
      return;
    case ati::Opcode::set_calibration:
      if (request.dlc < 1) break;
      ++counters_.calibration_requests;
      if (request.data[0] < config_.calibration_slots && request.data[0] < ati::kCalibrationCount) {
        active_calibration_ = request.data[0];
      }
      p[0] = active_calibration_;
      send(op, p, 1);
      return;
    case ati::Opcode::read_counts:
      store_be_u32(p, config_.calibration.counts_per_force);
      store_be_u32(p + 4, config_.calibration.counts_per_torque);
      send(op, p, 8);
      return;
    case ati::Opcode::read_units:
      p[0] = config_.calibration.force_unit;
      p[1] = config_.calibration.torque_unit;
      send(op, p, 2);
      return;
    case ati::Opcode::read_adc:
      if (request.dlc < 1 || request.data[0] > 5) break;
      store_be_u16(p, static_cast<std::uint16_t>(1000u + 100u * request.data[0]));
      send(op, p, 2);
      return;
    case ati::Opcode::reset: ++counters_.resets; return;
    case ati::Opcode::set_base_id:
      if (request.dlc < 1 || request.data[0] > ati::kMaxBaseId) break;
      p[0] = request.data[0];
      send(op, p, 1);  // acknowledged under the old ID, then the board answers to the new one
      base_id_ = request.data[0];
      return;
    case ati::Opcode::set_baud:
      if (request.dlc < 1) break;
      p[0] = request.data[0];
      send(op, p, 1);
      return;
    case ati::Opcode::read_firmware:
      p[0] = config_.firmware_major;
      p[1] = config_.firmware_minor;
      store_be_u16(p + 2, config_.firmware_build);
      send(op, p, 4);
      return;
    case ati::Opcode::gauges_second:
    case ati::Opcode::matrix_second:
    case ati::Opcode::matrix_third: break;
  }
  ++counters_.ignored_frames;
}

}  // namespace pliant::drivers::socketcan
