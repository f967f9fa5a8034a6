// pliant modbus driver: the Robotiq FT 300 wrist force/torque sensor as pure codecs (no I/O).
//
// Facts (Robotiq's rq_sensor_com.cpp, TRI robotiq_ft_driver; docs/drivers/modbus.md):
//   link       RS-485 Modbus RTU, 19200 baud 8N1, slave 9
//   polling    holding registers 180..185 (FC03) = Fx Fy Fz Mx My Mz as int16:
//              force = counts / 100 N, torque = counts / 1000 N m
//   streaming  an FC16 write of 0x0200 to register 410 starts a binary stream of 16-byte frames
//                0x20 0x4E | Fx Fy Fz Mx My Mz (int16 little-endian, same scales) | CRC-16
//              where the CRC (modbus_crc.hpp, low byte first) covers the first 14 bytes. The
//              sensor streams at about 100 Hz. Fifty 0xFF bytes ("jam signal") stop it; Modbus
//              answers again about 100 ms after the stream stopped.
// Wrench order everywhere in pliant: Fx Fy Fz (N), Tx Ty Tz (N m) in the sensor frame.
//
// Everything here is allocation-free and noexcept; the parser is a small fixed-size state
// machine (16-byte buffer) whose feed() is O(bytes fed). Not thread-safe: one parser per stream.
#pragma once

#include <cstddef>
#include <cstdint>

namespace pliant::drivers::modbus::ft300 {

inline constexpr int kDefaultSlaveId = 9;
inline constexpr int kDefaultBaud = 19200;   ///< 8N1
inline constexpr int kWrenchRegister = 180;  ///< Fx; Fy..Mz follow (FC03)
inline constexpr int kWrenchRegisterCount = 6;
inline constexpr int kStreamControlRegister = 410;  ///< FC16 kStreamStart here starts the stream
inline constexpr std::uint16_t kStreamStart = 0x0200;
inline constexpr double kForceCountsPerN = 100.0;
inline constexpr double kTorqueCountsPerNm = 1000.0;
inline constexpr std::size_t kFrameSize = 16;
inline constexpr std::uint8_t kFrameHeader0 = 0x20;
inline constexpr std::uint8_t kFrameHeader1 = 0x4e;
inline constexpr std::uint8_t kJamByte = 0xff;
inline constexpr std::size_t kJamLength = 50;
/// Size of the RTU frame encode_stream_start_request() writes.
inline constexpr std::size_t kStartRequestSize = 11;

/// Six raw counts (Fx Fy Fz Mx My Mz) -> wrench in N and N m.
void counts_to_wrench(const std::int16_t counts[6], double wrench[6]) noexcept;
/// The 6 registers read at kWrenchRegister (two's complement int16) -> wrench.
void registers_to_wrench(const std::uint16_t registers[kWrenchRegisterCount], double wrench[6]) noexcept;
/// The inverse (emulator, tests): rounded to the nearest count, saturated to int16; NaN -> 0.
void wrench_to_registers(const double wrench[6], std::uint16_t registers[kWrenchRegisterCount]) noexcept;
/// Wrench -> counts with the same rounding and saturation.
void wrench_to_counts(const double wrench[6], std::int16_t counts[6]) noexcept;

/// One stream frame (header, counts little-endian, CRC) from counts, into `out` (16 bytes).
void encode_stream_frame(const std::int16_t counts[6], std::uint8_t out[kFrameSize]) noexcept;

/// The RTU request that starts the stream: slave, 0x10, register 410, one register, two bytes,
/// 0x0200, CRC (kStartRequestSize bytes into `out`).
void encode_stream_start_request(std::uint8_t slave, std::uint8_t out[kStartRequestSize]) noexcept;

struct StreamFrame {
  std::int16_t counts[6] = {0, 0, 0, 0, 0, 0};  ///< raw Fx Fy Fz Mx My Mz
  double wrench[6] = {0, 0, 0, 0, 0, 0};        ///< N, N m
};

/// Monotonic parser counters (reset() clears them).
struct StreamParserCounters {
  std::uint64_t bytes = 0;          ///< bytes fed
  std::uint64_t frames = 0;         ///< frames with a valid CRC
  std::uint64_t crc_errors = 0;     ///< 16-byte candidates (header included) with a wrong CRC
  std::uint64_t garbage_bytes = 0;  ///< bytes dropped: not part of any valid frame
};

/// Finds frames in a byte stream. It hunts for the header 0x20 0x4E, collects 16 bytes and
/// checks the CRC. On a CRC mismatch it counts the error and resynchronises on the next header
/// inside the rejected bytes, so a valid frame that starts inside a corrupted one is not lost.
/// Frames may arrive split across any number of feed() calls. Every byte fed ends up either in
/// a valid frame, in garbage_bytes, or still buffered (pending(), < 16 bytes):
///   counters().bytes == 16 * frames + garbage_bytes + pending().
class StreamParser {
 public:
  /// Consumes `size` bytes (`data` may be null when size is 0). Returns the number of valid
  /// frames completed during this call; latest() is the last of them.
  std::size_t feed(const std::uint8_t* data, std::size_t size) noexcept;

  /// True once a valid frame was parsed since construction or reset().
  bool has_frame() const noexcept { return has_frame_; }
  /// The most recent valid frame (zeros before the first).
  const StreamFrame& latest() const noexcept { return latest_; }
  const StreamParserCounters& counters() const noexcept { return counters_; }
  /// Bytes held while waiting for the rest of a frame (0..15).
  std::size_t pending() const noexcept { return size_; }
  /// Forgets the buffered bytes, the latest frame and the counters.
  void reset() noexcept;

 private:
  void push(std::uint8_t byte) noexcept;
  void resync_after(std::size_t skip) noexcept;

  std::uint8_t buffer_[kFrameSize] = {};
  std::size_t size_ = 0;
  bool has_frame_ = false;
  std::size_t completed_ = 0;
  StreamFrame latest_;
  StreamParserCounters counters_;
};

}  // namespace pliant::drivers::modbus::ft300
