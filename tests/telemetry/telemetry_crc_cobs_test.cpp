// CRC-16/CCITT-FALSE check value and COBS against the encoding examples of the COBS paper
// (Cheshire and Baker 1999), as tabulated on Wikipedia's "Consistent Overhead Byte Stuffing".
#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <vector>

#include "pliant_telemetry.h"
#include "telemetry_test_support.hpp"

namespace pliant::telemetry_test {
namespace {

TEST(telemetry_crc, CheckValue) {
  const std::string text = "123456789";
  EXPECT_EQ(pliant_tm_crc16(reinterpret_cast<const std::uint8_t*>(text.data()), text.size()), 0x29B1u);
}

TEST(telemetry_crc, EmptyIsInitialValue) { EXPECT_EQ(pliant_tm_crc16(nullptr, 0), 0xFFFFu); }

TEST(telemetry_crc, SingleBytes) {
  // Reference values from an independent implementation (Python binascii.crc_hqx, init 0xFFFF).
  const std::uint8_t zero = 0x00;
  const std::uint8_t a = 'A';
  EXPECT_EQ(pliant_tm_crc16(&zero, 1), 0xE1F0u);
  EXPECT_EQ(pliant_tm_crc16(&a, 1), 0xB915u);
}

// Bytes lo, lo+1, ..., hi.
Bytes run(int lo, int hi) {
  Bytes b;
  for (int v = lo; v <= hi; ++v) b.push_back(static_cast<std::uint8_t>(v));
  return b;
}

Bytes cat(std::initializer_list<Bytes> parts) {
  Bytes out;
  for (const Bytes& p : parts) append(out, p);
  return out;
}

struct CobsVector {
  const char* name;
  Bytes decoded;
  Bytes encoded;  // without the delimiter
};

std::vector<CobsVector> cobs_vectors() {
  return {
      {"one_zero", {0x00}, {0x01, 0x01}},
      {"two_zeros", {0x00, 0x00}, {0x01, 0x01, 0x01}},
      {"zero_data_zero", {0x00, 0x11, 0x00}, {0x01, 0x02, 0x11, 0x01}},
      {"zero_inside", {0x11, 0x22, 0x00, 0x33}, {0x03, 0x11, 0x22, 0x02, 0x33}},
      {"no_zero", {0x11, 0x22, 0x33, 0x44}, {0x05, 0x11, 0x22, 0x33, 0x44}},
      {"trailing_zeros", {0x11, 0x00, 0x00, 0x00}, {0x02, 0x11, 0x01, 0x01, 0x01}},
      // 254 non-zero bytes fill one block exactly: no extra code byte.
      {"254_nonzero", run(0x01, 0xFE), cat({{0xFF}, run(0x01, 0xFE)})},
      {"zero_then_254", cat({{0x00}, run(0x01, 0xFE)}), cat({{0x01, 0xFF}, run(0x01, 0xFE)})},
      {"255_nonzero", run(0x01, 0xFF), cat({{0xFF}, run(0x01, 0xFE), {0x02, 0xFF}})},
      {"254_then_zero", cat({run(0x02, 0xFF), {0x00}}), cat({{0xFF}, run(0x02, 0xFF), {0x01, 0x01}})},
      {"253_zero_one", cat({run(0x03, 0xFF), {0x00, 0x01}}), cat({{0xFE}, run(0x03, 0xFF), {0x02, 0x01}})},
  };
}

TEST(telemetry_cobs, PaperExamplesEncode) {
  for (const CobsVector& v : cobs_vectors()) {
    Bytes out(v.decoded.size() + 8, 0xAA);
    const std::int32_t n = pliant_tm_cobs_encode(v.decoded.data(), v.decoded.size(), out.data(), out.size());
    ASSERT_GT(n, 0) << v.name;
    out.resize(static_cast<std::size_t>(n));
    EXPECT_EQ(out, v.encoded) << v.name;
  }
}

TEST(telemetry_cobs, PaperExamplesDecode) {
  for (const CobsVector& v : cobs_vectors()) {
    Bytes out(v.encoded.size(), 0xAA);
    const std::int32_t n = pliant_tm_cobs_decode(v.encoded.data(), v.encoded.size(), out.data(), out.size());
    ASSERT_GE(n, 0) << v.name;
    out.resize(static_cast<std::size_t>(n));
    EXPECT_EQ(out, v.decoded) << v.name;
  }
}

TEST(telemetry_cobs, DecodesInPlace) {
  for (const CobsVector& v : cobs_vectors()) {
    Bytes buffer = v.encoded;
    const std::int32_t n = pliant_tm_cobs_decode(buffer.data(), buffer.size(), buffer.data(), buffer.size());
    ASSERT_GE(n, 0) << v.name;
    buffer.resize(static_cast<std::size_t>(n));
    EXPECT_EQ(buffer, v.decoded) << v.name;
  }
}

TEST(telemetry_cobs, EmptyInputIsOneCodeByte) {
  std::uint8_t out[2] = {0xAA, 0xAA};
  EXPECT_EQ(pliant_tm_cobs_encode(nullptr, 0, out, sizeof out), 1);
  EXPECT_EQ(out[0], 0x01);
}

TEST(telemetry_cobs, EncodedSizeBoundAndNoZeros) {
  for (std::size_t n : {1u, 2u, 253u, 254u, 255u, 507u, 508u, 509u, 1024u}) {
    for (int pattern = 0; pattern < 3; ++pattern) {
      Bytes in(n);
      for (std::size_t i = 0; i < n; ++i) {
        in[i] = pattern == 0 ? 0x55 : pattern == 1 ? 0x00 : static_cast<std::uint8_t>(i * 37 % 256);
      }
      Bytes out(n + n / 254 + 4);
      const std::int32_t size = pliant_tm_cobs_encode(in.data(), n, out.data(), out.size());
      ASSERT_GT(size, 0);
      EXPECT_LE(static_cast<std::size_t>(size), n + (n + 253) / 254) << n << " pattern " << pattern;
      for (std::int32_t i = 0; i < size; ++i) ASSERT_NE(out[static_cast<std::size_t>(i)], 0) << i;
      Bytes back(static_cast<std::size_t>(size));
      const std::int32_t m =
          pliant_tm_cobs_decode(out.data(), static_cast<std::size_t>(size), back.data(), back.size());
      ASSERT_EQ(m, static_cast<std::int32_t>(n));
      back.resize(n);
      EXPECT_EQ(back, in);
    }
  }
  // The largest packet: all 1024 bytes non-zero is the worst case, 1029 bytes encoded.
  Bytes in(PLIANT_TM_MAX_PACKET, 0x7F);
  Bytes out(PLIANT_TM_MAX_FRAME);
  EXPECT_EQ(pliant_tm_cobs_encode(in.data(), in.size(), out.data(), out.size()),
            static_cast<std::int32_t>(PLIANT_TM_MAX_FRAME - 1));
  EXPECT_EQ(PLIANT_TM_FRAME_SIZE(PLIANT_TM_MAX_PACKET), PLIANT_TM_MAX_FRAME);
}

TEST(telemetry_cobs, EncodeRefusesSmallBuffer) {
  const Bytes in = {0x11, 0x22, 0x00, 0x33};
  Bytes out(4, 0xAA);  // needs 5
  EXPECT_EQ(pliant_tm_cobs_encode(in.data(), in.size(), out.data(), out.size()), PLIANT_TM_E_NO_ROOM);
  EXPECT_EQ(pliant_tm_cobs_encode(in.data(), in.size(), out.data(), 0), PLIANT_TM_E_NO_ROOM);
  EXPECT_EQ(pliant_tm_cobs_encode(in.data(), in.size(), nullptr, 8), PLIANT_TM_E_ARGUMENT);
  EXPECT_EQ(pliant_tm_cobs_encode(nullptr, 3, out.data(), out.size()), PLIANT_TM_E_ARGUMENT);
}

TEST(telemetry_cobs, DecodeRejectsMalformed) {
  Bytes out(16);
  const Bytes past_end = {0x05, 0x11, 0x22};   // code promises 4 bytes, 2 follow
  const Bytes zero_code = {0x00, 0x11};        // a zero can never appear
  const Bytes zero_data = {0x03, 0x11, 0x00};  // nor inside a block
  const Bytes full_block_short = {0xFF, 0x01, 0x02};
  for (const Bytes& bad : {past_end, zero_code, zero_data, full_block_short}) {
    EXPECT_EQ(pliant_tm_cobs_decode(bad.data(), bad.size(), out.data(), out.size()), PLIANT_TM_E_ARGUMENT);
  }
  EXPECT_EQ(pliant_tm_cobs_decode(out.data(), 0, out.data(), out.size()), PLIANT_TM_E_ARGUMENT);
  const Bytes good = {0x05, 0x11, 0x22, 0x33, 0x44};
  EXPECT_EQ(pliant_tm_cobs_decode(good.data(), good.size(), out.data(), 3), PLIANT_TM_E_NO_ROOM);
}

}  // namespace
}  // namespace pliant::telemetry_test
