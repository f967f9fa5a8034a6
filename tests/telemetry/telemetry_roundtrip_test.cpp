// Encoder -> decoder round trips of every message type (NaN and infinities included), the exact
// byte layout of docs/telemetry.md, particle chunking and the encoders' refusals.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <vector>

#include "pliant_telemetry.h"
#include "telemetry_test_support.hpp"

namespace pliant::telemetry_test {
namespace {

Decoded decode_one(const Bytes& frame) {
  pliant_tm_decoder_t dec;
  pliant_tm_decoder_init(&dec);
  const std::vector<Decoded> got = decode_all(dec, frame);
  EXPECT_EQ(dec.counters.frames, 1u);
  EXPECT_EQ(drops(dec.counters), 0u);
  if (got.size() != 1) throw std::runtime_error("expected one message, got " + std::to_string(got.size()));
  return got.front();
}

std::uint64_t get_u64(const Bytes& b, std::size_t at) {
  std::uint64_t v = 0;
  for (int i = 7; i >= 0; --i) v = (v << 8) | b[at + static_cast<std::size_t>(i)];
  return v;
}
std::uint32_t get_u32(const Bytes& b, std::size_t at) {
  return static_cast<std::uint32_t>(get_u64(Bytes{b[at], b[at + 1], b[at + 2], b[at + 3], 0, 0, 0, 0}, 0));
}
std::uint16_t get_u16(const Bytes& b, std::size_t at) { return static_cast<std::uint16_t>(b[at] | (b[at + 1] << 8)); }

TEST(telemetry_layout, EstimatePacketIsTheDocumentedBytes) {
  pliant_tm_encoder_t enc;
  pliant_tm_encoder_init(&enc, 0x1234);
  const Bytes frame = estimate_frame(enc, 0x0102030405060708ull, sample_estimate());
  const Bytes packet = packet_of(frame);
  ASSERT_EQ(packet.size(), PLIANT_TM_HEADER_SIZE + 29u + PLIANT_TM_CRC_SIZE);
  EXPECT_EQ(frame.size(), PLIANT_TM_FRAME_SIZE(packet.size()));
  EXPECT_EQ(packet[0], 1);
  EXPECT_EQ(packet[1], PLIANT_TM_TYPE_ESTIMATE);
  EXPECT_EQ(packet[2], 0x34);  // little-endian seq
  EXPECT_EQ(packet[3], 0x12);
  EXPECT_EQ((Bytes{packet.begin() + 4, packet.begin() + 12}), (Bytes{8, 7, 6, 5, 4, 3, 2, 1}));
  // msm_beta 0.375 = 0x3FD8000000000000, msm_beta_std 0.0625 = 0x3FB0000000000000.
  EXPECT_EQ((Bytes{packet.begin() + 12, packet.begin() + 20}), (Bytes{0, 0, 0, 0, 0, 0, 0xD8, 0x3F}));
  EXPECT_EQ(get_u64(packet, 20), 0x3FB0000000000000ull);
  double rms = 0;
  const std::uint64_t rms_bits = get_u64(packet, 28);
  std::memcpy(&rms, &rms_bits, sizeof rms);
  EXPECT_EQ(rms, 1.5e-4);
  EXPECT_EQ(get_u32(packet, 36), 123456u);
  EXPECT_EQ(packet[40], 0x03);
  EXPECT_EQ(get_u16(packet, 41), pliant_tm_crc16(packet.data(), 41));
  EXPECT_EQ(frame.back(), 0);
  for (std::size_t i = 0; i + 1 < frame.size(); ++i) EXPECT_NE(frame[i], 0) << i;
}

TEST(telemetry_layout, VerdictPacketIsTheDocumentedBytes) {
  pliant_tm_encoder_t enc;
  pliant_tm_encoder_init(&enc, 7);
  const pliant_tm_verdict_t v = sample_verdict();
  const Bytes packet = packet_of(verdict_frame(enc, 99, v));
  ASSERT_EQ(packet.size(), PLIANT_TM_HEADER_SIZE + 52u + PLIANT_TM_CRC_SIZE);
  EXPECT_EQ(packet[1], PLIANT_TM_TYPE_VERDICT);
  EXPECT_EQ((Bytes{packet.begin() + 12, packet.begin() + 16}), (Bytes{1, 14, 1, 0x04}));
  EXPECT_EQ(get_u32(packet, 16), (1u << 14) | (1u << 12));
  EXPECT_EQ(packet[20], PLIANT_TM_VERDICT_IN_CONTACT);
  EXPECT_EQ((Bytes{packet.begin() + 21, packet.begin() + 24}), (Bytes{0, 0, 0}));
  const float expected[10] = {v.closure_m,        v.force_n,        v.strain,       v.allowed_force_n,
                              v.predicted_strain, v.safe_closure_m, v.safe_width_m, v.predicted_force_n,
                              v.beta_low,         v.beta_high};
  for (std::size_t i = 0; i < 10; ++i) {
    const std::uint32_t bits = get_u32(packet, 24 + 4 * i);
    float value = 0;
    std::memcpy(&value, &bits, sizeof value);
    EXPECT_EQ(value, expected[i]) << i;
  }
}

TEST(telemetry_layout, ParticlesAndCountersPayloadSizes) {
  pliant_tm_encoder_t enc;
  pliant_tm_encoder_init(&enc, 0);
  const ParticleFrame f3 = make_particle_frame(4, 3, 5);
  const std::vector<Bytes> chunks = particle_chunks(enc, 1, f3);
  ASSERT_EQ(chunks.size(), 1u);
  const Bytes packet = packet_of(chunks[0]);
  EXPECT_EQ(packet.size(), 12u + 12u + 5u * 13u + 2u);
  EXPECT_EQ(get_u32(packet, 12), 4u);
  EXPECT_EQ(packet[16], 3);
  EXPECT_EQ(packet[17], 0);
  EXPECT_EQ(get_u16(packet, 18), 5);
  EXPECT_EQ(get_u16(packet, 20), 0);
  EXPECT_EQ(get_u16(packet, 22), 5);
  EXPECT_EQ(packet[24 + 12], f3.status[0]);
  const ParticleFrame f2 = make_particle_frame(4, 2, 5);
  EXPECT_EQ(packet_of(particle_chunks(enc, 1, f2)[0]).size(), 12u + 12u + 5u * 9u + 2u);
  const Bytes counters = packet_of(counters_frame(enc, 1, {{1, 10}, {8, 0xDEADBEEF}}));
  EXPECT_EQ(counters.size(), 12u + 2u + 2u * 6u + 2u);
  EXPECT_EQ(get_u16(counters, 12), 2);
  EXPECT_EQ(get_u16(counters, 20), 8);
  EXPECT_EQ(get_u32(counters, 22), 0xDEADBEEFu);
}

TEST(telemetry_roundtrip, Estimate) {
  pliant_tm_encoder_t enc;
  pliant_tm_encoder_init(&enc, 41);
  const pliant_tm_estimate_t e = sample_estimate();
  const Decoded d = decode_one(estimate_frame(enc, 123456789012ull, e));
  EXPECT_EQ(d.header.version, 1);
  EXPECT_EQ(d.header.type, PLIANT_TM_TYPE_ESTIMATE);
  EXPECT_EQ(d.header.seq, 41);
  EXPECT_EQ(d.header.stamp_us, 123456789012ull);
  EXPECT_EQ(d.estimate.msm_beta, e.msm_beta);
  EXPECT_EQ(d.estimate.msm_beta_std, e.msm_beta_std);
  EXPECT_EQ(d.estimate.rms, e.rms);
  EXPECT_EQ(d.estimate.frames, e.frames);
  EXPECT_EQ(d.estimate.flags, e.flags);
  EXPECT_EQ(enc.next_seq, 42);
}

TEST(telemetry_roundtrip, EstimateNonFinite) {
  pliant_tm_encoder_t enc;
  pliant_tm_encoder_init(&enc, 0);
  // A NaN with a payload and the sign bit set must come back bit for bit.
  double payload_nan = 0;
  const std::uint64_t bits = 0xFFF8000000000ABCull;
  std::memcpy(&payload_nan, &bits, sizeof payload_nan);
  const double values[][3] = {{kNaN, kInf, -kInf}, {payload_nan, -0.0, kNaN}, {0.0, kInf, 1e308}};
  for (const auto& v : values) {
    pliant_tm_estimate_t e{};
    e.msm_beta = v[0];
    e.msm_beta_std = v[1];
    e.rms = v[2];
    e.flags = 0xF0;  // unknown bits travel as given
    const Decoded d = decode_one(estimate_frame(enc, 0, e));
    EXPECT_TRUE(same_bits(d.estimate.msm_beta, e.msm_beta));
    EXPECT_TRUE(same_bits(d.estimate.msm_beta_std, e.msm_beta_std));
    EXPECT_TRUE(same_bits(d.estimate.rms, e.rms));
    EXPECT_EQ(d.estimate.flags, 0xF0);
  }
}

TEST(telemetry_roundtrip, Verdict) {
  pliant_tm_encoder_t enc;
  pliant_tm_encoder_init(&enc, 0xFFFF);
  pliant_tm_verdict_t v = sample_verdict();
  v.safe_width_m = kNaNf;
  v.predicted_force_n = kInff;
  v.strain = -kInff;
  v.beta_low = -0.0f;
  const Decoded d = decode_one(verdict_frame(enc, 5, v));
  EXPECT_EQ(d.header.seq, 0xFFFF);
  EXPECT_EQ(enc.next_seq, 0);  // wraps
  EXPECT_EQ(d.verdict.verdict, v.verdict);
  EXPECT_EQ(d.verdict.reason, v.reason);
  EXPECT_EQ(d.verdict.stop_action, v.stop_action);
  EXPECT_EQ(d.verdict.fault_sources, v.fault_sources);
  EXPECT_EQ(d.verdict.reasons, v.reasons);
  EXPECT_EQ(d.verdict.flags, v.flags);
  const float* const got[10] = {&d.verdict.closure_m,       &d.verdict.force_n,           &d.verdict.strain,
                                &d.verdict.allowed_force_n, &d.verdict.predicted_strain,  &d.verdict.safe_closure_m,
                                &d.verdict.safe_width_m,    &d.verdict.predicted_force_n, &d.verdict.beta_low,
                                &d.verdict.beta_high};
  const float want[10] = {v.closure_m,        v.force_n,        v.strain,       v.allowed_force_n,
                          v.predicted_strain, v.safe_closure_m, v.safe_width_m, v.predicted_force_n,
                          v.beta_low,         v.beta_high};
  for (int i = 0; i < 10; ++i) EXPECT_TRUE(same_bits(*got[i], want[i])) << i;
}

TEST(telemetry_roundtrip, VerdictExtremeCodes) {
  pliant_tm_encoder_t enc;
  pliant_tm_encoder_init(&enc, 0);
  pliant_tm_verdict_t v = sample_verdict();
  v.verdict = 2;
  v.reason = 18;
  v.stop_action = 0;
  v.fault_sources = 0x1F;
  v.reasons = (1u << 19) - 1u;
  v.flags = 0xFF;
  const Decoded d = decode_one(verdict_frame(enc, 5, v));
  EXPECT_EQ(d.verdict.reason, 18);
  EXPECT_EQ(d.verdict.fault_sources, 0x1F);
  EXPECT_EQ(d.verdict.reasons, (1u << 19) - 1u);
  EXPECT_EQ(d.verdict.flags, 0xFF);
}

void expect_particles(const ParticleFrame& f, const std::vector<Decoded>& chunks) {
  std::vector<int> seen(f.total(), 0);
  for (const Decoded& c : chunks) {
    ASSERT_EQ(c.header.type, PLIANT_TM_TYPE_PARTICLES);
    EXPECT_EQ(c.particles.frame, f.frame);
    EXPECT_EQ(c.particles.dim, f.dim);
    EXPECT_EQ(c.particles.total, f.total());
    for (std::uint16_t i = 0; i < c.particles.count; ++i) {
      const std::size_t id = static_cast<std::size_t>(c.particles.first) + i;
      ++seen[id];
      for (std::size_t axis = 0; axis < 3; ++axis) {
        const float want = axis < f.dim ? f.positions[id * f.dim + axis] : 0.0f;
        EXPECT_TRUE(same_bits(c.positions[3 * i + axis], want)) << id << " axis " << axis;
      }
      EXPECT_EQ(c.status[i], f.status[id]) << id;
    }
  }
  for (std::size_t id = 0; id < seen.size(); ++id) EXPECT_EQ(seen[id], 1) << id;
}

TEST(telemetry_roundtrip, ParticlesChunkedAtEveryCapacity) {
  for (const std::uint8_t dim : {std::uint8_t{2}, std::uint8_t{3}}) {
    ParticleFrame f = make_particle_frame(17, dim, 300);
    f.positions[4] = kNaNf;
    f.positions[7] = kInff;
    for (std::size_t capacity :
         {std::size_t{PLIANT_TM_MAX_FRAME}, std::size_t{600}, std::size_t{255}, std::size_t{64}}) {
      pliant_tm_encoder_t enc;
      pliant_tm_encoder_init(&enc, 0);
      const std::vector<Bytes> chunks = particle_chunks(enc, 77, f, capacity);
      const std::uint16_t per = pliant_tm_particles_per_chunk(dim, capacity);
      EXPECT_EQ(chunks.size(), (300u + per - 1u) / per) << int(dim) << " " << capacity;
      Bytes stream;
      for (const Bytes& c : chunks) {
        EXPECT_LE(c.size(), capacity);
        append(stream, c);
      }
      // The chunk size is the largest whose worst-case frame fits: one more particle does not.
      if (per < PLIANT_TM_MAX_CHUNK_PARTICLES(dim)) {
        const std::size_t packet = 26u + (per + 1u) * PLIANT_TM_PARTICLE_SIZE(std::size_t{dim});
        EXPECT_GT(PLIANT_TM_FRAME_SIZE(packet), capacity) << int(dim) << " " << capacity;
      }
      pliant_tm_decoder_t dec;
      pliant_tm_decoder_init(&dec);
      expect_particles(f, decode_all(dec, stream));
      EXPECT_EQ(dec.counters.messages, chunks.size());
      EXPECT_EQ(drops(dec.counters), 0u);
      EXPECT_EQ(dec.counters.seq_missed, 0u);
    }
  }
}

TEST(telemetry_roundtrip, ParticleChunkLimits) {
  EXPECT_EQ(PLIANT_TM_MAX_CHUNK_PARTICLES(2u), 110u);
  EXPECT_EQ(PLIANT_TM_MAX_CHUNK_PARTICLES(3u), 76u);
  EXPECT_EQ(pliant_tm_particles_per_chunk(3, PLIANT_TM_MAX_FRAME), 76u);
  EXPECT_EQ(pliant_tm_particles_per_chunk(2, PLIANT_TM_MAX_FRAME), 110u);
  EXPECT_EQ(pliant_tm_particles_per_chunk(3, 100000), 76u);
  EXPECT_EQ(pliant_tm_particles_per_chunk(4, PLIANT_TM_MAX_FRAME), 0u);
  // 26 fixed bytes + 13 per 3D particle, COBS +1, delimiter +1: 41 bytes hold one particle.
  EXPECT_EQ(pliant_tm_particles_per_chunk(3, 41), 1u);
  EXPECT_EQ(pliant_tm_particles_per_chunk(3, 40), 0u);
  // A full 76-particle 3D chunk is a 26 + 988 = 1014-byte packet: its frame is at most
  // 1014 + 4 + 1 bytes, and exactly 1014 + 1 + 1 here since zero bytes (status 0) end every block.
  const ParticleFrame f = make_particle_frame(0, 3, 76);
  pliant_tm_encoder_t enc;
  pliant_tm_encoder_init(&enc, 0);
  EXPECT_EQ(particle_chunks(enc, 0, f)[0].size(), 1016u);
  const ParticleFrame big = make_particle_frame(0, 3, 77);
  const pliant_tm_particle_frame_t view = big.view();
  Bytes out(PLIANT_TM_MAX_FRAME);
  EXPECT_EQ(pliant_tm_encode_particles(&enc, 0, &view, 0, 77, out.data(), out.size()), PLIANT_TM_E_TOO_LARGE);
}

TEST(telemetry_roundtrip, ParticlesNextSplitsLikePerChunk) {
  const ParticleFrame f = make_particle_frame(5, 3, 200);
  const pliant_tm_particle_frame_t view = f.view();
  for (std::size_t capacity : {std::size_t{PLIANT_TM_MAX_FRAME}, std::size_t{300}, std::size_t{41}}) {
    pliant_tm_encoder_t by_hand;
    pliant_tm_encoder_init(&by_hand, 9);
    const std::vector<Bytes> expected = particle_chunks(by_hand, 44, f, capacity);
    pliant_tm_encoder_t enc;
    pliant_tm_encoder_init(&enc, 9);
    std::vector<Bytes> got;
    std::uint16_t next = 0;
    do {
      Bytes out(capacity);
      const std::int32_t n = pliant_tm_encode_particles_next(&enc, 44, &view, &next, out.data(), out.size());
      ASSERT_GT(n, 0) << capacity;
      out.resize(static_cast<std::size_t>(n));
      got.push_back(out);
    } while (next < view.total && got.size() < 1000);
    EXPECT_EQ(next, view.total);
    EXPECT_EQ(got, expected) << capacity;
  }
  pliant_tm_encoder_t enc;
  pliant_tm_encoder_init(&enc, 0);
  Bytes out(PLIANT_TM_MAX_FRAME);
  std::uint16_t next = 201;
  EXPECT_EQ(pliant_tm_encode_particles_next(&enc, 0, &view, &next, out.data(), out.size()), PLIANT_TM_E_ARGUMENT);
  next = 0;
  EXPECT_EQ(pliant_tm_encode_particles_next(&enc, 0, &view, &next, out.data(), 40), PLIANT_TM_E_NO_ROOM);
  EXPECT_EQ(next, 0u);
  EXPECT_EQ(pliant_tm_encode_particles_next(&enc, 0, &view, nullptr, out.data(), out.size()), PLIANT_TM_E_ARGUMENT);
  // A frame without particles is one empty chunk.
  const ParticleFrame empty = make_particle_frame(6, 2, 0);
  const pliant_tm_particle_frame_t empty_view = empty.view();
  EXPECT_GT(pliant_tm_encode_particles_next(&enc, 0, &empty_view, &next, out.data(), out.size()), 0);
  EXPECT_EQ(next, 0u);
  EXPECT_EQ(enc.next_seq, 1u);
}

TEST(telemetry_roundtrip, EmptyParticleFrame) {
  const ParticleFrame f = make_particle_frame(3, 2, 0);
  pliant_tm_encoder_t enc;
  pliant_tm_encoder_init(&enc, 0);
  const std::vector<Bytes> chunks = particle_chunks(enc, 0, f);
  ASSERT_EQ(chunks.size(), 1u);
  const Decoded d = decode_one(chunks[0]);
  EXPECT_EQ(d.particles.total, 0u);
  EXPECT_EQ(d.particles.count, 0u);
}

TEST(telemetry_roundtrip, Counters) {
  pliant_tm_encoder_t enc;
  pliant_tm_encoder_init(&enc, 0);
  for (std::size_t n : {std::size_t{0}, std::size_t{1}, std::size_t{15}, std::size_t{PLIANT_TM_MAX_COUNTERS}}) {
    std::vector<pliant_tm_counter_t> counters;
    for (std::size_t i = 0; i < n; ++i) {
      counters.push_back({static_cast<std::uint16_t>(i * 389 + 1), static_cast<std::uint32_t>(0xFFFFFFF0u + i)});
    }
    const Bytes frame = counters_frame(enc, 9, counters);
    EXPECT_LE(frame.size(), PLIANT_TM_MAX_FRAME);
    const Decoded d = decode_one(frame);
    ASSERT_EQ(d.counters.size(), n);
    for (std::size_t i = 0; i < n; ++i) {
      EXPECT_EQ(d.counters[i].id, counters[i].id);
      EXPECT_EQ(d.counters[i].value, counters[i].value);
    }
  }
  EXPECT_EQ(PLIANT_TM_MAX_COUNTERS, 168u);
}

TEST(telemetry_roundtrip, CounterNames) {
  EXPECT_STREQ(pliant_tm_counter_name(1), "tracker_frames");
  EXPECT_STREQ(pliant_tm_counter_name(8), "guard_cycles");
  EXPECT_STREQ(pliant_tm_counter_name(15), "bridge_calls_rejected");
  EXPECT_EQ(pliant_tm_counter_name(0), nullptr);
  EXPECT_EQ(pliant_tm_counter_name(16), nullptr);
  for (std::uint16_t id = 1; id <= 15; ++id) EXPECT_NE(pliant_tm_counter_name(id), nullptr) << id;
}

TEST(telemetry_encoder, NoRoomLeavesSequenceAlone) {
  pliant_tm_encoder_t enc;
  pliant_tm_encoder_init(&enc, 10);
  Bytes out(PLIANT_TM_MAX_FRAME);
  const pliant_tm_estimate_t e = sample_estimate();
  const pliant_tm_verdict_t v = sample_verdict();
  const std::int32_t estimate_size = pliant_tm_encode_estimate(&enc, 0, &e, out.data(), out.size());
  const std::int32_t verdict_size = pliant_tm_encode_verdict(&enc, 0, &v, out.data(), out.size());
  EXPECT_EQ(estimate_size, 45);
  EXPECT_EQ(verdict_size, 68);
  EXPECT_EQ(enc.next_seq, 12);
  EXPECT_EQ(pliant_tm_encode_estimate(&enc, 0, &e, out.data(), 44), PLIANT_TM_E_NO_ROOM);
  EXPECT_EQ(pliant_tm_encode_verdict(&enc, 0, &v, out.data(), 67), PLIANT_TM_E_NO_ROOM);
  EXPECT_EQ(pliant_tm_encode_verdict(&enc, 0, &v, out.data(), 0), PLIANT_TM_E_NO_ROOM);
  const pliant_tm_counter_t c[2] = {{1, 2}, {3, 4}};
  EXPECT_EQ(pliant_tm_encode_counters(&enc, 0, c, 2, out.data(), 20), PLIANT_TM_E_NO_ROOM);
  EXPECT_EQ(enc.next_seq, 12);
  // Exactly the frame size is enough, and nothing is written past it.
  Bytes exact(45 + 4, 0xAA);
  EXPECT_EQ(pliant_tm_encode_estimate(&enc, 0, &e, exact.data(), 45), 45);
  for (std::size_t i = 45; i < exact.size(); ++i) EXPECT_EQ(exact[i], 0xAA);
}

TEST(telemetry_encoder, RefusesOutOfRangeFields) {
  pliant_tm_encoder_t enc;
  pliant_tm_encoder_init(&enc, 0);
  Bytes out(PLIANT_TM_MAX_FRAME);
  const auto verdict_with = [](auto change) {
    pliant_tm_verdict_t v = sample_verdict();
    change(v);
    return v;
  };
  const pliant_tm_verdict_t bad_verdicts[] = {
      verdict_with([](pliant_tm_verdict_t& v) { v.verdict = 3; }),
      verdict_with([](pliant_tm_verdict_t& v) { v.reason = 19; }),
      verdict_with([](pliant_tm_verdict_t& v) { v.stop_action = 2; }),
      verdict_with([](pliant_tm_verdict_t& v) { v.fault_sources = 0x20; }),
      verdict_with([](pliant_tm_verdict_t& v) { v.reasons = 1u << 19; }),
  };
  for (const pliant_tm_verdict_t& v : bad_verdicts) {
    EXPECT_EQ(pliant_tm_encode_verdict(&enc, 0, &v, out.data(), out.size()), PLIANT_TM_E_ARGUMENT);
  }
  ParticleFrame f = make_particle_frame(0, 3, 10);
  pliant_tm_particle_frame_t view = f.view();
  EXPECT_EQ(pliant_tm_encode_particles(&enc, 0, &view, 5, 6, out.data(), out.size()), PLIANT_TM_E_ARGUMENT);
  view.dim = 4;
  EXPECT_EQ(pliant_tm_encode_particles(&enc, 0, &view, 0, 1, out.data(), out.size()), PLIANT_TM_E_ARGUMENT);
  f.status[2] = 3;
  view = f.view();
  EXPECT_EQ(pliant_tm_encode_particles(&enc, 0, &view, 0, 3, out.data(), out.size()), PLIANT_TM_E_ARGUMENT);
  EXPECT_GT(pliant_tm_encode_particles(&enc, 0, &view, 3, 3, out.data(), out.size()), 0);  // 2 not in the chunk
  view.positions = nullptr;
  EXPECT_EQ(pliant_tm_encode_particles(&enc, 0, &view, 0, 1, out.data(), out.size()), PLIANT_TM_E_ARGUMENT);
  const pliant_tm_counter_t duplicate[2] = {{4, 1}, {4, 2}};
  EXPECT_EQ(pliant_tm_encode_counters(&enc, 0, duplicate, 2, out.data(), out.size()), PLIANT_TM_E_ARGUMENT);
  EXPECT_EQ(pliant_tm_encode_counters(&enc, 0, nullptr, 1, out.data(), out.size()), PLIANT_TM_E_ARGUMENT);
  std::vector<pliant_tm_counter_t> many(PLIANT_TM_MAX_COUNTERS + 1);
  for (std::size_t i = 0; i < many.size(); ++i) many[i].id = static_cast<std::uint16_t>(i);
  EXPECT_EQ(
      pliant_tm_encode_counters(&enc, 0, many.data(), static_cast<std::uint16_t>(many.size()), out.data(), out.size()),
      PLIANT_TM_E_TOO_LARGE);
  const pliant_tm_estimate_t e = sample_estimate();
  EXPECT_EQ(pliant_tm_encode_estimate(nullptr, 0, &e, out.data(), out.size()), PLIANT_TM_E_ARGUMENT);
  EXPECT_EQ(pliant_tm_encode_estimate(&enc, 0, nullptr, out.data(), out.size()), PLIANT_TM_E_ARGUMENT);
  EXPECT_EQ(pliant_tm_encode_estimate(&enc, 0, &e, nullptr, 100), PLIANT_TM_E_ARGUMENT);
  EXPECT_EQ(enc.next_seq, 1);  // only the good particles chunk took a number
}

}  // namespace
}  // namespace pliant::telemetry_test
