// The FT 300 stream parser: clean frames, frames split anywhere, garbage, CRC errors, resync on
// a header inside a rejected candidate, the byte accounting invariant, and a long random stream.
#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <vector>

#include "pliant/drivers/modbus/ft300_codec.hpp"

namespace pliant::drivers::modbus::ft300 {
namespace {

std::vector<std::uint8_t> frame_of(std::int16_t fx, std::int16_t fy = 0, std::int16_t fz = 0, std::int16_t mx = 0,
                                   std::int16_t my = 0, std::int16_t mz = 0) {
  const std::int16_t counts[6] = {fx, fy, fz, mx, my, mz};
  std::vector<std::uint8_t> f(kFrameSize);
  encode_stream_frame(counts, f.data());
  return f;
}

void append(std::vector<std::uint8_t>& to, const std::vector<std::uint8_t>& bytes) {
  to.insert(to.end(), bytes.begin(), bytes.end());
}

void expect_accounting(const StreamParser& p) {
  const StreamParserCounters& c = p.counters();
  EXPECT_EQ(c.bytes, 16 * c.frames + c.garbage_bytes + p.pending());
}

TEST(Ft300StreamParser, OneCleanFrame) {
  StreamParser p;
  const auto f = frame_of(150, -250, 1000, 500, -1500, 32767);
  EXPECT_EQ(p.feed(f.data(), f.size()), 1u);
  ASSERT_TRUE(p.has_frame());
  EXPECT_EQ(p.latest().counts[0], 150);
  EXPECT_EQ(p.latest().counts[1], -250);
  EXPECT_DOUBLE_EQ(p.latest().wrench[0], 1.5);
  EXPECT_DOUBLE_EQ(p.latest().wrench[1], -2.5);
  EXPECT_DOUBLE_EQ(p.latest().wrench[2], 10.0);
  EXPECT_DOUBLE_EQ(p.latest().wrench[3], 0.5);
  EXPECT_DOUBLE_EQ(p.latest().wrench[4], -1.5);
  EXPECT_DOUBLE_EQ(p.latest().wrench[5], 32.767);
  EXPECT_EQ(p.counters().frames, 1u);
  EXPECT_EQ(p.counters().crc_errors, 0u);
  EXPECT_EQ(p.counters().garbage_bytes, 0u);
  EXPECT_EQ(p.pending(), 0u);
  expect_accounting(p);
}

TEST(Ft300StreamParser, FrameSplitAtEveryPoint) {
  const auto f = frame_of(-7, 8, -9, 10, -11, 12);
  for (std::size_t cut = 0; cut <= f.size(); ++cut) {
    StreamParser p;
    EXPECT_EQ(p.feed(f.data(), cut), cut == f.size() ? 1u : 0u);
    EXPECT_EQ(p.pending(), cut == f.size() ? 0u : cut);
    EXPECT_EQ(p.feed(f.data() + cut, f.size() - cut), cut == f.size() ? 0u : 1u);
    ASSERT_TRUE(p.has_frame()) << cut;
    EXPECT_EQ(p.latest().counts[5], 12);
    expect_accounting(p);
  }
  StreamParser bytewise;
  std::size_t frames = 0;
  for (std::uint8_t b : f) frames += bytewise.feed(&b, 1);
  EXPECT_EQ(frames, 1u);
  EXPECT_EQ(bytewise.feed(nullptr, 0), 0u);
}

TEST(Ft300StreamParser, GarbageIsSkippedAndCounted) {
  StreamParser p;
  std::vector<std::uint8_t> s = {0x00, 0x20, 0x11, 0x4e, 0x20, 0x20};  // two 0x20 before the real header
  append(s, frame_of(42));
  EXPECT_EQ(p.feed(s.data(), s.size()), 1u);
  EXPECT_EQ(p.latest().counts[0], 42);
  // All six: each buffered 0x20 is dropped when the byte after it is not 0x4E, the last one when
  // the real header's own 0x20 arrives.
  EXPECT_EQ(p.counters().garbage_bytes, 6u);
  EXPECT_EQ(p.counters().crc_errors, 0u);
  expect_accounting(p);
  // The jam signal (fifty 0xFF) and a Modbus answer are plain garbage.
  StreamParser q;
  std::vector<std::uint8_t> jam(kJamLength, kJamByte);
  const std::vector<std::uint8_t> answer = {0x09, 0x10, 0x01, 0x9a, 0x00, 0x01, 0x21, 0x4e};
  append(jam, answer);
  EXPECT_EQ(q.feed(jam.data(), jam.size()), 0u);
  EXPECT_EQ(q.counters().garbage_bytes, kJamLength + answer.size());
  EXPECT_FALSE(q.has_frame());
  expect_accounting(q);
}

TEST(Ft300StreamParser, CrcErrorIsCountedAndTheNextFrameRecovered) {
  StreamParser p;
  auto bad = frame_of(100, 200);
  bad[5] ^= 0x40;  // flip one data bit
  std::vector<std::uint8_t> s = bad;
  append(s, frame_of(300, 400));
  EXPECT_EQ(p.feed(s.data(), s.size()), 1u);
  EXPECT_EQ(p.counters().crc_errors, 1u);
  EXPECT_EQ(p.counters().frames, 1u);
  EXPECT_EQ(p.counters().garbage_bytes, 16u);
  EXPECT_EQ(p.latest().counts[0], 300);
  expect_accounting(p);
  // A damaged CRC byte alone is enough.
  StreamParser q;
  auto bad_crc = frame_of(1);
  bad_crc[15] ^= 0x01;
  EXPECT_EQ(q.feed(bad_crc.data(), bad_crc.size()), 0u);
  EXPECT_EQ(q.counters().crc_errors, 1u);
  EXPECT_FALSE(q.has_frame());
}

TEST(Ft300StreamParser, ResynchronisesOnAHeaderInsideARejectedCandidate) {
  // A frame cut short after 7 bytes (a lost byte run on the line), then a whole frame: the
  // 16-byte candidate fails its CRC and the parser restarts at the second header, not after it.
  const auto a = frame_of(11, 22, 33);
  const auto b = frame_of(-44, -55, -66);
  std::vector<std::uint8_t> s(a.begin(), a.begin() + 7);
  append(s, b);
  StreamParser p;
  EXPECT_EQ(p.feed(s.data(), s.size()), 1u);
  EXPECT_EQ(p.counters().crc_errors, 1u);
  EXPECT_EQ(p.counters().garbage_bytes, 7u);
  EXPECT_EQ(p.latest().counts[0], -44);
  EXPECT_EQ(p.latest().counts[2], -66);
  expect_accounting(p);
}

TEST(Ft300StreamParser, SeveralFramesInOneFeedKeepTheLatest) {
  std::vector<std::uint8_t> s;
  for (std::int16_t i = 1; i <= 5; ++i) append(s, frame_of(i));
  s.push_back(0x20);  // the start of a sixth frame
  StreamParser p;
  EXPECT_EQ(p.feed(s.data(), s.size()), 5u);
  EXPECT_EQ(p.latest().counts[0], 5);
  EXPECT_EQ(p.pending(), 1u);
  expect_accounting(p);
  p.reset();
  EXPECT_FALSE(p.has_frame());
  EXPECT_EQ(p.pending(), 0u);
  EXPECT_EQ(p.counters().bytes, 0u);
  EXPECT_EQ(p.latest().counts[0], 0);
}

TEST(Ft300StreamParser, LongRandomStreamLosesNoValidFrame) {
  // Valid frames between random garbage that is rich in 0x20 and 0x4E, fed in random pieces.
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> byte(0, 255);
  std::uniform_int_distribution<int> pick(0, 9);
  std::vector<std::uint8_t> s;
  std::vector<std::int16_t> sent;
  for (int k = 0; k < 2000; ++k) {
    const int garbage = pick(rng);
    for (int g = 0; g < garbage; ++g) {
      const int r = pick(rng);
      s.push_back(r < 3 ? std::uint8_t{0x20} : r < 5 ? std::uint8_t{0x4e} : static_cast<std::uint8_t>(byte(rng)));
    }
    const auto value = static_cast<std::int16_t>(byte(rng) * 100 - 12800);
    append(s, frame_of(value, static_cast<std::int16_t>(k)));
    sent.push_back(value);
  }
  StreamParser p;
  std::size_t at = 0;
  std::size_t frames = 0;
  std::vector<std::int16_t> got;
  while (at < s.size()) {
    const std::size_t n = std::min<std::size_t>(s.size() - at, static_cast<std::size_t>(1 + byte(rng) % 40));
    const std::size_t before = p.counters().frames;
    frames += p.feed(s.data() + at, n);
    if (p.counters().frames != before) got.push_back(p.latest().counts[0]);
    at += n;
  }
  EXPECT_EQ(frames, sent.size());
  EXPECT_EQ(p.counters().frames, sent.size());
  EXPECT_EQ(p.counters().frames * 16 + p.counters().garbage_bytes + p.pending(), s.size());
  EXPECT_EQ(p.pending(), 0u);
  EXPECT_FALSE(got.empty());
  EXPECT_EQ(got.back(), sent.back());
}

}  // namespace
}  // namespace pliant::drivers::modbus::ft300
