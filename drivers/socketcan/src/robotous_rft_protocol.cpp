#include "pliant/drivers/socketcan/robotous_rft_protocol.hpp"

#include <cstring>

namespace pliant::drivers::socketcan::rft {

bool valid(const Ids& ids) noexcept {
  return ids.command <= kCanSffMask && ids.response_1 <= kCanSffMask && ids.response_2 <= kCanSffMask &&
         ids.command != ids.response_1 && ids.command != ids.response_2 && ids.response_1 != ids.response_2;
}

CanFrame make_command(const Ids& ids, std::uint8_t code, std::uint8_t arg) noexcept {
  const std::uint8_t payload[8] = {code, arg, 0, 0, 0, 0, 0, 0};
  return make_standard_frame(ids.command, payload, 8);
}

FrameRole classify(const CanFrame& frame, const Ids& ids) noexcept {
  if (!is_standard_data_frame(frame)) return FrameRole::foreign;
  const bool first = frame.id == ids.response_1;
  const bool second = frame.id == ids.response_2;
  if (!first && !second) return FrameRole::foreign;
  if (frame.dlc != 8) return FrameRole::wrong_dlc;
  return first ? FrameRole::first : FrameRole::second;
}

PacketError decode_ft_packet(const std::uint8_t packet[kPacketSize], FtPacket& out) noexcept {
  if (packet[0] != kCmdFtOnce && packet[0] != kCmdFtStart) return PacketError::not_ft;
  FtPacket p;
  p.command = packet[0];
  for (int i = 0; i < 6; ++i) p.raw[i] = load_be_i16(packet + 1 + 2 * i);
  p.overload = packet[13];
  out = p;
  return PacketError::none;
}

void encode_ft_packet(std::uint8_t command, const std::int16_t raw[6], std::uint8_t overload,
                      std::uint8_t packet[kPacketSize]) noexcept {
  std::memset(packet, 0, kPacketSize);
  packet[0] = command;
  for (int i = 0; i < 6; ++i) store_be_i16(packet + 1 + 2 * i, raw[i]);
  packet[13] = overload;
}

void split_packet(const Ids& ids, const std::uint8_t packet[kPacketSize], CanFrame& first, CanFrame& second) noexcept {
  first = make_standard_frame(ids.response_1, packet, 8);
  second = make_standard_frame(ids.response_2, packet + 8, 8);
}

void raw_to_wrench(const std::int16_t raw[6], double force_divider, double torque_divider, double wrench[6]) noexcept {
  for (int i = 0; i < 3; ++i) {
    wrench[i] = static_cast<double>(raw[i]) / force_divider;
    wrench[3 + i] = static_cast<double>(raw[3 + i]) / torque_divider;
  }
}

PacketAssembler::Result PacketAssembler::add(FrameRole role, const CanFrame& frame) noexcept {
  if (role == FrameRole::first) {
    const bool replaced = holding_;
    std::memcpy(packet_, frame.data, 8);
    holding_ = true;
    return replaced ? Result::replaced_first : Result::partial;
  }
  if (role != FrameRole::second) return Result::ignored;
  if (!holding_) return Result::orphan_second;
  std::memcpy(packet_ + 8, frame.data, 8);
  holding_ = false;
  return Result::complete;
}

bool PacketAssembler::reset() noexcept {
  const bool held = holding_;
  holding_ = false;
  return held;
}

}  // namespace pliant::drivers::socketcan::rft
