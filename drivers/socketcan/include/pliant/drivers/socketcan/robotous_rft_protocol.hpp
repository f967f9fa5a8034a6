// pliant socketcan driver: the Robotous RFT (RFT40/60/80) CAN protocol, pure (no I/O).
// Sources: Robotous's packet header RFT_IF_PACKET Rev1.0 and CAN sample, CORC RobotousRFT;
// per fact in docs/drivers/socketcan.md, "Device facts we rely on".
//
// IDs: one command ID (host -> sensor; sample default 0x64) and two response IDs (sensor ->
// host; defaults 0x01 and 0x02), all standard 11-bit, 1 Mbit/s.
// Command: one 8-byte frame, byte 0 the command code, the rest arguments (zero padded).
// Response: a 16-byte packet split over the two response IDs: bytes 0-7 on response ID 1,
// bytes 8-15 on response ID 2, sent in that order. Byte 0 echoes the command.
// F/T packet (commands 10 "once" and 11 "stream"):
//   [0] command  [1..12] Fx Fy Fz Tx Ty Tz as int16 big-endian  [13] overload flags  [14..15] pad
//   F = raw / force_divider (N), T = raw / torque_divider (N m); the dividers depend on the
//   model (commonly 50 and 2000). Note that Tx straddles the two frames.
// Commands used here: 11 start streaming, 12 stop streaming (no response), 17 set bias
// (arg 1 on: the sensor zeroes itself on its current load; 0 off; no response), 15 set output
// rate (arg: 0 = 200 Hz default, 1 = 10, 2 = 20, 3 = 50, 4 = 100, 5 = 200, 6 = 300, 7 = 500,
// 8 = 1000 Hz).
//
// Everything here is deterministic, allocation-free, noexcept and O(1).
#pragma once

#include <cstdint>

#include "pliant/drivers/socketcan/can_frame.hpp"

namespace pliant::drivers::socketcan::rft {

inline constexpr std::uint8_t kCmdProductName = 1;
inline constexpr std::uint8_t kCmdSerialNumber = 2;
inline constexpr std::uint8_t kCmdFirmware = 3;
inline constexpr std::uint8_t kCmdFtOnce = 10;
inline constexpr std::uint8_t kCmdFtStart = 11;
inline constexpr std::uint8_t kCmdFtStop = 12;
inline constexpr std::uint8_t kCmdSetOutputRate = 15;
inline constexpr std::uint8_t kCmdGetOutputRate = 16;
inline constexpr std::uint8_t kCmdSetBias = 17;
inline constexpr std::uint8_t kCmdOverloadCount = 18;
inline constexpr std::uint8_t kMaxOutputRateCode = 8;
inline constexpr std::uint8_t kPacketSize = 16;

struct Ids {
  std::uint16_t command = 0x64;     ///< host -> sensor
  std::uint16_t response_1 = 0x01;  ///< packet bytes 0-7
  std::uint16_t response_2 = 0x02;  ///< packet bytes 8-15
};
/// All three IDs standard (<= 0x7ff) and distinct.
bool valid(const Ids& ids) noexcept;

/// The 8-byte command frame: [code, arg, 0...].
CanFrame make_command(const Ids& ids, std::uint8_t code, std::uint8_t arg = 0) noexcept;

/// Which half of a response a frame is.
enum class FrameRole : std::uint8_t {
  first,      ///< response ID 1, DLC 8
  second,     ///< response ID 2, DLC 8
  foreign,    ///< not a standard data frame on a response ID
  wrong_dlc,  ///< a response ID with DLC != 8
};
FrameRole classify(const CanFrame& frame, const Ids& ids) noexcept;

/// A decoded F/T packet.
struct FtPacket {
  std::uint8_t command = 0;  ///< 10 or 11
  std::int16_t raw[6] = {0, 0, 0, 0, 0, 0};
  std::uint8_t overload = 0;
};
enum class PacketError : std::uint8_t { none = 0, not_ft };
/// Decodes a 16-byte packet; not_ft (out untouched) when byte 0 is not 10 or 11.
PacketError decode_ft_packet(const std::uint8_t packet[kPacketSize], FtPacket& out) noexcept;
/// The two frames of a packet (the emulator's side).
void split_packet(const Ids& ids, const std::uint8_t packet[kPacketSize], CanFrame& first, CanFrame& second) noexcept;
/// The 16-byte F/T packet for `command` (10 or 11), raw values and overload byte.
void encode_ft_packet(std::uint8_t command, const std::int16_t raw[6], std::uint8_t overload,
                      std::uint8_t packet[kPacketSize]) noexcept;

/// wrench[6] = raw / divider (forces, then torques). Dividers must be finite and > 0.
void raw_to_wrench(const std::int16_t raw[6], double force_divider, double torque_divider, double wrench[6]) noexcept;

/// Pairs first and second halves into packets. Frames must come first-then-second (one node
/// sends them back to back, and CAN keeps one node's order); a second half with no first, or
/// a first half while one is held, breaks a pair and is reported so the caller can count it.
class PacketAssembler {
 public:
  enum class Result : std::uint8_t {
    partial,         ///< a first half is held
    complete,        ///< packet() holds 16 bytes; the assembler is empty again
    replaced_first,  ///< a first half arrived while one was held: the older one was discarded
    orphan_second,   ///< a second half with no first: discarded
    ignored,         ///< role foreign or wrong_dlc: not a half of any packet
  };
  Result add(FrameRole role, const CanFrame& frame) noexcept;
  /// Forgets a held first half. True if one was held.
  bool reset() noexcept;
  bool holding() const noexcept { return holding_; }
  const std::uint8_t* packet() const noexcept { return packet_; }

 private:
  std::uint8_t packet_[kPacketSize] = {};
  bool holding_ = false;
};

}  // namespace pliant::drivers::socketcan::rft
