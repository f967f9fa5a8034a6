#include "pliant/drivers/modbus/ft300_codec.hpp"

#include <cmath>
#include <cstring>

#include "pliant/drivers/modbus/modbus_crc.hpp"

namespace pliant::drivers::modbus::ft300 {
namespace {

// Two's complement without implementation-defined narrowing.
constexpr std::int16_t to_i16(std::uint16_t u) noexcept {
  return u < 0x8000u ? static_cast<std::int16_t>(u) : static_cast<std::int16_t>(static_cast<int>(u) - 0x10000);
}
constexpr std::uint16_t to_u16(std::int16_t v) noexcept {
  return static_cast<std::uint16_t>(static_cast<std::int32_t>(v) & 0xffff);
}

double scale_of(int axis) noexcept { return axis < 3 ? kForceCountsPerN : kTorqueCountsPerNm; }

std::int16_t saturate(double counts) noexcept {
  if (std::isnan(counts)) return 0;
  if (counts >= 32767.0) return 32767;
  if (counts <= -32768.0) return -32768;
  return static_cast<std::int16_t>(std::lround(counts));
}

}  // namespace

void counts_to_wrench(const std::int16_t counts[6], double wrench[6]) noexcept {
  for (int i = 0; i < 6; ++i) wrench[i] = static_cast<double>(counts[i]) / scale_of(i);
}

void registers_to_wrench(const std::uint16_t registers[kWrenchRegisterCount], double wrench[6]) noexcept {
  std::int16_t counts[6];
  for (int i = 0; i < 6; ++i) counts[i] = to_i16(registers[i]);
  counts_to_wrench(counts, wrench);
}

void wrench_to_counts(const double wrench[6], std::int16_t counts[6]) noexcept {
  for (int i = 0; i < 6; ++i) counts[i] = saturate(wrench[i] * scale_of(i));
}

void wrench_to_registers(const double wrench[6], std::uint16_t registers[kWrenchRegisterCount]) noexcept {
  std::int16_t counts[6];
  wrench_to_counts(wrench, counts);
  for (int i = 0; i < 6; ++i) registers[i] = to_u16(counts[i]);
}

void encode_stream_frame(const std::int16_t counts[6], std::uint8_t out[kFrameSize]) noexcept {
  out[0] = kFrameHeader0;
  out[1] = kFrameHeader1;
  for (std::size_t i = 0; i < 6; ++i) {
    const std::uint16_t u = to_u16(counts[i]);
    out[2 + 2 * i] = static_cast<std::uint8_t>(u & 0xffu);
    out[3 + 2 * i] = static_cast<std::uint8_t>(u >> 8);
  }
  append_modbus_crc16(out, kFrameSize - 2);
}

void encode_stream_start_request(std::uint8_t slave, std::uint8_t out[kStartRequestSize]) noexcept {
  out[0] = slave;
  out[1] = 0x10;  // write multiple registers
  out[2] = static_cast<std::uint8_t>(kStreamControlRegister >> 8);
  out[3] = static_cast<std::uint8_t>(kStreamControlRegister & 0xff);
  out[4] = 0x00;  // one register
  out[5] = 0x01;
  out[6] = 0x02;  // two data bytes
  out[7] = static_cast<std::uint8_t>(kStreamStart >> 8);
  out[8] = static_cast<std::uint8_t>(kStreamStart & 0xffu);
  append_modbus_crc16(out, 9);
}

void StreamParser::reset() noexcept {
  size_ = 0;
  has_frame_ = false;
  completed_ = 0;
  latest_ = StreamFrame{};
  counters_ = StreamParserCounters{};
}

std::size_t StreamParser::feed(const std::uint8_t* data, std::size_t size) noexcept {
  completed_ = 0;
  for (std::size_t i = 0; i < size; ++i) push(data[i]);
  counters_.bytes += size;
  return completed_;
}

void StreamParser::push(std::uint8_t byte) noexcept {
  if (size_ == 0) {
    if (byte == kFrameHeader0) {
      buffer_[size_++] = byte;
    } else {
      ++counters_.garbage_bytes;
    }
    return;
  }
  if (size_ == 1 && byte != kFrameHeader1) {
    // The buffered 0x20 did not start a frame; this byte may start the next one.
    ++counters_.garbage_bytes;
    size_ = 0;
    push(byte);
    return;
  }
  buffer_[size_++] = byte;
  if (size_ < kFrameSize) return;
  if (check_modbus_crc16(buffer_, kFrameSize)) {
    for (std::size_t i = 0; i < 6; ++i) {
      const auto u = static_cast<std::uint16_t>(buffer_[2 + 2 * i] | (static_cast<unsigned>(buffer_[3 + 2 * i]) << 8));
      latest_.counts[i] = to_i16(u);
    }
    counts_to_wrench(latest_.counts, latest_.wrench);
    has_frame_ = true;
    ++counters_.frames;
    ++completed_;
    size_ = 0;
    return;
  }
  ++counters_.crc_errors;
  resync_after(1);
}

// Drops the first bytes of a rejected 16-byte candidate up to the next possible header
// (0x20 followed by 0x4E, or a 0x20 in the last position) at or after `skip`.
void StreamParser::resync_after(std::size_t skip) noexcept {
  std::size_t start = size_;
  for (std::size_t i = skip; i < size_; ++i) {
    if (buffer_[i] == kFrameHeader0 && (i + 1 == size_ || buffer_[i + 1] == kFrameHeader1)) {
      start = i;
      break;
    }
  }
  counters_.garbage_bytes += start;
  std::memmove(buffer_, buffer_ + start, size_ - start);
  size_ -= start;
}

}  // namespace pliant::drivers::modbus::ft300
