// libFuzzer target over the Robotiq FT 300 stream parser (drivers/modbus/src/ft300_codec.cpp).
//
// Byte 0 of an input picks how the rest is cut into pieces (1..64 bytes, or one piece when 0).
// Any byte stream must be consumed without a crash or sanitizer report, and:
//   - the accounting holds after every piece: bytes == 16 * frames + garbage + pending, and
//     pending < 16; the frames feed() reports add up to the counter;
//   - the latest frame re-encodes to a frame with a valid CRC whose counts scale to its wrench;
//   - the result does not depend on the cut: feeding everything at once gives the same counters
//     and the same latest frame.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>

#include "pliant/drivers/modbus/ft300_codec.hpp"
#include "pliant/drivers/modbus/modbus_crc.hpp"

namespace {

namespace ft300 = pliant::drivers::modbus::ft300;

void check(bool condition) {
  if (!condition) std::abort();
}

void check_frame(const ft300::StreamFrame& f) {
  std::uint8_t bytes[ft300::kFrameSize];
  ft300::encode_stream_frame(f.counts, bytes);
  check(bytes[0] == ft300::kFrameHeader0 && bytes[1] == ft300::kFrameHeader1);
  check(pliant::drivers::modbus::check_modbus_crc16(bytes, ft300::kFrameSize));
  double wrench[6];
  ft300::counts_to_wrench(f.counts, wrench);
  for (int i = 0; i < 6; ++i) check(wrench[i] == f.wrench[i]);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::size_t piece = data[0] == 0 ? size : 1 + data[0] % 64;
  const std::uint8_t* bytes = data + 1;
  const std::size_t n = size - 1;

  ft300::StreamParser split;
  std::uint64_t reported = 0;
  for (std::size_t at = 0; at < n; at += piece) {
    const std::size_t len = n - at < piece ? n - at : piece;
    reported += split.feed(bytes + at, len);
    const ft300::StreamParserCounters& c = split.counters();
    check(split.pending() < ft300::kFrameSize);
    check(c.bytes == 16 * c.frames + c.garbage_bytes + split.pending());
    check(c.bytes == at + len);
  }
  check(reported == split.counters().frames);
  check(split.has_frame() == (split.counters().frames > 0));
  if (split.has_frame()) check_frame(split.latest());

  ft300::StreamParser whole;
  check(whole.feed(bytes, n) == whole.counters().frames);
  const ft300::StreamParserCounters& a = split.counters();
  const ft300::StreamParserCounters& b = whole.counters();
  check(a.bytes == b.bytes && a.frames == b.frames && a.crc_errors == b.crc_errors &&
        a.garbage_bytes == b.garbage_bytes);
  check(split.pending() == whole.pending());
  check(std::memcmp(split.latest().counts, whole.latest().counts, sizeof split.latest().counts) == 0);
  return 0;
}
