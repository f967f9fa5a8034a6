#include "pliant/drivers/socketcan/emulator/robotous_rft_emulator.hpp"

#include <cmath>
#include <cstring>
#include <limits>

#include "pliant/drivers/socketcan/can_error.hpp"

namespace pliant::drivers::socketcan {

namespace {

constexpr std::int16_t kMin = std::numeric_limits<std::int16_t>::min();
constexpr std::int16_t kMax = std::numeric_limits<std::int16_t>::max();

std::int16_t saturate(double v) noexcept {
  if (std::isnan(v)) return 0;
  if (v <= -32768.0) return kMin;
  if (v >= 32767.0) return kMax;
  return static_cast<std::int16_t>(std::lround(v));
}

std::int16_t saturate(std::int32_t v) noexcept {
  if (v < kMin) return kMin;
  if (v > kMax) return kMax;
  return static_cast<std::int16_t>(v);
}

}  // namespace

RobotousRftEmulator::RobotousRftEmulator(CanTransport& link, const RftEmulatorConfig& config) noexcept
    : link_(&link), config_(config) {}

void RobotousRftEmulator::set_raw(const std::int16_t raw[6]) noexcept { std::memcpy(raw_, raw, sizeof raw_); }

void RobotousRftEmulator::set_wrench(const double wrench[6]) noexcept {
  for (int i = 0; i < 6; ++i) raw_[i] = saturate(wrench[i] * (i < 3 ? config_.force_divider : config_.torque_divider));
}

void RobotousRftEmulator::send(const CanFrame& frame) noexcept { (void)send_raw(frame); }

CanIo RobotousRftEmulator::send_raw(const CanFrame& frame) noexcept {
  const CanIo io = link_->send(frame);
  if (io != CanIo::ok) ++counters_.send_failures;
  return io;
}

CanIo RobotousRftEmulator::send_error(std::uint32_t classes, const std::uint8_t* data8) noexcept {
  return send_raw(make_can_error_frame(classes, data8));
}

int RobotousRftEmulator::service(int max_commands) noexcept {
  int n = 0;
  while (n < max_commands && link_->is_open()) {
    CanFrame f;
    CanRxInfo info;
    const CanIo io = link_->receive(f, info);
    if (io == CanIo::empty || io == CanIo::disconnected || io == CanIo::io_error) break;
    ++n;
    if (io != CanIo::ok || !is_standard_data_frame(f) || f.id != config_.ids.command || f.dlc != 8) {
      ++counters_.ignored_frames;
      continue;
    }
    ++counters_.commands;
    if (!faults_.mute) handle(f);
  }
  return n;
}

void RobotousRftEmulator::send_response(std::uint8_t b0, std::uint8_t b1) noexcept {
  std::uint8_t packet[rft::kPacketSize] = {};
  packet[0] = b0;
  packet[1] = b1;
  CanFrame first, second;
  rft::split_packet(config_.ids, packet, first, second);
  send(first);
  send(second);
}

void RobotousRftEmulator::handle(const CanFrame& frame) noexcept {
  switch (frame.data[0]) {
    case rft::kCmdFtOnce: send_packet(rft::kCmdFtOnce); return;
    case rft::kCmdFtStart:
      ++counters_.stream_starts;
      streaming_ = true;
      return;
    case rft::kCmdFtStop:
      ++counters_.stream_stops;
      streaming_ = false;
      return;
    case rft::kCmdSetBias:
      ++counters_.bias_commands;
      bias_active_ = frame.data[1] == 1;
      if (bias_active_) {
        std::memcpy(bias_, raw_, sizeof bias_);
      } else {
        std::memset(bias_, 0, sizeof bias_);
      }
      return;
    case rft::kCmdSetOutputRate:
      ++counters_.rate_commands;
      if (frame.data[1] <= rft::kMaxOutputRateCode) rate_code_ = frame.data[1];
      send_response(rft::kCmdSetOutputRate, 1);
      return;
    case rft::kCmdGetOutputRate: send_response(rft::kCmdGetOutputRate, static_cast<std::uint8_t>(rate_code_)); return;
    default: ++counters_.ignored_frames; return;
  }
}

void RobotousRftEmulator::send_packet(std::uint8_t command) noexcept {
  std::int16_t out[6];
  for (int i = 0; i < 6; ++i)
    out[i] = saturate(static_cast<std::int32_t>(raw_[i]) - static_cast<std::int32_t>(bias_[i]));
  std::uint8_t packet[rft::kPacketSize];
  rft::encode_ft_packet(command, out, overload_, packet);
  CanFrame first, second;
  rft::split_packet(config_.ids, packet, first, second);
  bool send_first = true, send_second = true, swap = false;
  if (faults_.drop_first_halves > 0) {
    --faults_.drop_first_halves;
    send_first = false;
  }
  if (faults_.drop_second_halves > 0) {
    --faults_.drop_second_halves;
    send_second = false;
  }
  if (faults_.swap_halves > 0) {
    --faults_.swap_halves;
    swap = true;
  }
  if (faults_.wrong_dlc > 0) {
    --faults_.wrong_dlc;
    second.dlc = 7;
    second.data[7] = 0;
  }
  if (swap && send_second) send(second);
  if (send_first) send(first);
  if (!swap && send_second) send(second);
  ++counters_.packets_sent;
}

int RobotousRftEmulator::stream(int packets) noexcept {
  if (!streaming_ || faults_.mute) return 0;
  int sent = 0;
  for (; sent < packets; ++sent) send_packet(rft::kCmdFtStart);
  return sent;
}

}  // namespace pliant::drivers::socketcan
