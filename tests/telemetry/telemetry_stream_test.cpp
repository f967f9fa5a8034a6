// Streaming decoder: any split of the byte stream, garbage before and between frames, every
// corruption class counted under its own reason, sequence gaps, truncation at the end.
#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "pliant_telemetry.h"
#include "telemetry_test_support.hpp"

namespace pliant::telemetry_test {
namespace {

// A stream of every message type, with multi-chunk particle frames: 1 + 1 + 4 + 1 + ... frames.
struct Sample {
  Bytes stream;
  std::size_t frames = 0;
  std::vector<std::uint8_t> types;
};

Sample sample_stream(std::uint16_t first_seq = 0) {
  Sample s;
  pliant_tm_encoder_t enc;
  pliant_tm_encoder_init(&enc, first_seq);
  const auto add = [&](const Bytes& frame, std::uint8_t type) {
    append(s.stream, frame);
    ++s.frames;
    s.types.push_back(type);
  };
  for (std::uint32_t k = 0; k < 3; ++k) {
    add(estimate_frame(enc, 1000 * k, sample_estimate()), PLIANT_TM_TYPE_ESTIMATE);
    add(verdict_frame(enc, 1000 * k + 1, sample_verdict()), PLIANT_TM_TYPE_VERDICT);
    for (const Bytes& chunk : particle_chunks(enc, 1000 * k + 2, make_particle_frame(k, 3, 250))) {
      add(chunk, PLIANT_TM_TYPE_PARTICLES);
    }
    add(counters_frame(enc, 1000 * k + 3, {{1, k}, {8, 100 * k}, {999, 7}}), PLIANT_TM_TYPE_COUNTERS);
  }
  return s;
}

void expect_consistent(const pliant_tm_decoder_counters_t& c) {
  EXPECT_EQ(c.frames, c.messages + drops(c)) << "every frame is delivered or counted once";
}

void expect_types(const std::vector<Decoded>& got, const std::vector<std::uint8_t>& types) {
  ASSERT_EQ(got.size(), types.size());
  for (std::size_t i = 0; i < got.size(); ++i) EXPECT_EQ(got[i].header.type, types[i]) << i;
}

TEST(telemetry_stream, WholeStreamInOnePush) {
  const Sample s = sample_stream();
  pliant_tm_decoder_t dec;
  pliant_tm_decoder_init(&dec);
  const std::vector<Decoded> got = decode_all(dec, s.stream);
  expect_types(got, s.types);
  EXPECT_EQ(dec.counters.messages, s.frames);
  EXPECT_EQ(drops(dec.counters), 0u);
  EXPECT_EQ(dec.counters.seq_missed, 0u);
  for (std::size_t i = 0; i < got.size(); ++i) EXPECT_EQ(got[i].header.seq, i);
  expect_consistent(dec.counters);
}

TEST(telemetry_stream, ByteAtATime) {
  const Sample s = sample_stream(65530);  // the sequence wraps inside the stream
  pliant_tm_decoder_t dec;
  pliant_tm_decoder_init(&dec);
  const std::vector<Decoded> got = decode_all(dec, s.stream, {1});
  expect_types(got, s.types);
  EXPECT_EQ(drops(dec.counters), 0u);
  EXPECT_EQ(dec.counters.seq_missed, 0u);
  EXPECT_EQ(dec.counters.seq_backward, 0u);
  // Particle payloads survive byte-wise delivery.
  for (const Decoded& d : got) {
    if (d.header.type == PLIANT_TM_TYPE_PARTICLES) {
      const ParticleFrame f = make_particle_frame(d.particles.frame, 3, 250);
      for (std::uint16_t i = 0; i < d.particles.count; ++i) {
        EXPECT_EQ(d.positions[3u * i + 1u], f.positions[(d.particles.first + i) * 3u + 1u]);
        EXPECT_EQ(d.status[i], f.status[d.particles.first + i]);
      }
    }
  }
}

TEST(telemetry_stream, RandomSplits) {
  const Sample s = sample_stream();
  std::mt19937 rng(1234);
  for (int trial = 0; trial < 50; ++trial) {
    std::uniform_int_distribution<std::size_t> size(1, trial % 2 == 0 ? 16 : 2500);
    std::vector<std::size_t> pieces(64);
    for (std::size_t& p : pieces) p = size(rng);
    pliant_tm_decoder_t dec;
    pliant_tm_decoder_init(&dec);
    const std::vector<Decoded> got = decode_all(dec, s.stream, pieces);
    expect_types(got, s.types);
    EXPECT_EQ(drops(dec.counters), 0u) << trial;
  }
}

// Number of non-empty runs between zero bytes (each is one frame to the decoder).
std::size_t runs(const Bytes& bytes) {
  std::size_t n = 0;
  bool in_run = false;
  for (std::uint8_t b : bytes) {
    if (b == 0) {
      n += in_run ? 1 : 0;
      in_run = false;
    } else {
      in_run = true;
    }
  }
  return n + (in_run ? 1 : 0);
}

TEST(telemetry_stream, GarbageBeforeAndBetweenFrames) {
  std::mt19937 rng(99);
  std::uniform_int_distribution<int> byte(0, 255);
  std::uniform_int_distribution<int> length(1, 300);
  const auto garbage = [&] {
    Bytes g(static_cast<std::size_t>(length(rng)));
    for (std::uint8_t& b : g) b = static_cast<std::uint8_t>(byte(rng));
    g.push_back(0);  // the receiver resynchronises at the next delimiter
    return g;
  };
  pliant_tm_encoder_t enc;
  pliant_tm_encoder_init(&enc, 0);
  Bytes stream;
  std::size_t garbage_runs = 0;
  std::size_t good = 0;
  for (int k = 0; k < 40; ++k) {
    const Bytes g = garbage();
    garbage_runs += runs(g);
    append(stream, g);
    append(stream, k % 2 == 0 ? verdict_frame(enc, static_cast<std::uint64_t>(k), sample_verdict())
                              : estimate_frame(enc, static_cast<std::uint64_t>(k), sample_estimate()));
    ++good;
  }
  for (const std::vector<std::size_t>& pieces : {std::vector<std::size_t>{}, {1}, {7, 300, 2}}) {
    pliant_tm_decoder_t dec;
    pliant_tm_decoder_init(&dec);
    const std::vector<Decoded> got = decode_all(dec, stream, pieces);
    ASSERT_EQ(got.size(), good);
    for (std::size_t i = 0; i < got.size(); ++i) EXPECT_EQ(got[i].header.stamp_us, i);
    EXPECT_EQ(drops(dec.counters), garbage_runs);
    EXPECT_EQ(dec.counters.frames, good + garbage_runs);
    EXPECT_EQ(dec.counters.seq_missed, 0u);
    expect_consistent(dec.counters);
  }
}

TEST(telemetry_stream, EmptyFramesAreIgnored) {
  pliant_tm_encoder_t enc;
  pliant_tm_encoder_init(&enc, 0);
  Bytes stream = {0, 0, 0};
  append(stream, estimate_frame(enc, 1, sample_estimate()));
  append(stream, Bytes{0, 0});
  append(stream, estimate_frame(enc, 2, sample_estimate()));
  pliant_tm_decoder_t dec;
  pliant_tm_decoder_init(&dec);
  EXPECT_EQ(decode_all(dec, stream).size(), 2u);
  EXPECT_EQ(dec.counters.frames, 2u);
  EXPECT_EQ(drops(dec.counters), 0u);
}

// One kind of damage: the bytes that replace a good frame and the counter they must land in.
struct Corruption {
  std::string name;
  Bytes frame;
  std::uint32_t pliant_tm_decoder_counters_t::*counter;
};

Bytes estimate_payload(std::size_t size) {
  Bytes p(size, 0x11);
  return p;
}

Bytes verdict_payload(std::uint8_t verdict, std::uint8_t reason, std::uint8_t stop, std::uint8_t faults,
                      std::uint32_t reasons) {
  Bytes p{verdict, reason, stop, faults};
  put_u32(p, reasons);
  p.insert(p.end(), 4, 0);  // flags, reserved
  for (int i = 0; i < 10; ++i) put_f32(p, 1.0f);
  return p;
}

Bytes particles_payload(std::uint8_t dim, std::uint16_t total, std::uint16_t first, std::uint16_t count,
                        std::size_t items, std::uint8_t status = 0) {
  Bytes p;
  put_u32(p, 5);
  p.push_back(dim);
  p.push_back(0);
  put_u16(p, total);
  put_u16(p, first);
  put_u16(p, count);
  for (std::size_t i = 0; i < items; ++i) {
    for (std::uint8_t a = 0; a < (dim == 2 ? 2 : 3); ++a) put_f32(p, 0.5f);
    p.push_back(status);
  }
  return p;
}

Bytes counters_payload(std::uint16_t count, const std::vector<std::uint16_t>& ids) {
  Bytes p;
  put_u16(p, count);
  for (std::uint16_t id : ids) {
    put_u16(p, id);
    put_u32(p, 1);
  }
  return p;
}

std::vector<Corruption> corruptions() {
  using C = pliant_tm_decoder_counters_t;
  pliant_tm_encoder_t enc;
  pliant_tm_encoder_init(&enc, 0);
  std::vector<Corruption> list;
  // COBS: a code byte promising more bytes than the frame has.
  list.push_back({"cobs_code_past_end", {0x09, 0x11, 0x22, 0x00}, &C::cobs_error});
  Bytes cut = estimate_frame(enc, 0, sample_estimate());
  cut[0] = 0xF0;  // the first block now claims 239 bytes
  list.push_back({"cobs_first_code_too_long", cut, &C::cobs_error});
  // CRC: one payload bit flipped, COBS re-applied so only the CRC can notice.
  Bytes flipped = packet_of(verdict_frame(enc, 0, sample_verdict()));
  flipped[30] ^= 0x04;
  list.push_back({"crc_payload_bit", frame_of(flipped), &C::crc_mismatch});
  Bytes bad_crc = packet_of(estimate_frame(enc, 0, sample_estimate()));
  bad_crc.back() ^= 0x80;
  list.push_back({"crc_trailer_bit", frame_of(bad_crc), &C::crc_mismatch});
  Bytes bad_version_byte = packet_of(estimate_frame(enc, 0, sample_estimate()));
  bad_version_byte[0] = 2;  // corrupted in transit: the CRC catches it first
  list.push_back({"crc_first_byte", frame_of(bad_version_byte), &C::crc_mismatch});
  // Oversize: no delimiter within 1030 bytes, and a well-formed frame holding a 1026-byte packet.
  Bytes endless(1500, 0x42);
  endless.push_back(0);
  list.push_back({"oversize_no_delimiter", endless, &C::oversize});
  Bytes exactly_too_long(PLIANT_TM_MAX_FRAME, 0x42);  // 1030 non-zero bytes, then the delimiter
  exactly_too_long.push_back(0);
  list.push_back({"oversize_1030_bytes", exactly_too_long, &C::oversize});
  Bytes big_packet(1026, 0);
  for (std::size_t i = 0; i < big_packet.size(); i += 2) big_packet[i] = 0x33;
  list.push_back({"oversize_packet", frame_of(with_crc(big_packet)), &C::oversize});
  // Short: fewer than 14 bytes.
  list.push_back({"short_13", frame_of(Bytes(13, 0x01)), &C::short_packet});
  list.push_back({"short_1", Bytes{0x02, 0x07, 0x00}, &C::short_packet});
  // Version 2 with a good CRC.
  list.push_back({"version_2", crafted_frame(PLIANT_TM_TYPE_ESTIMATE, 0, estimate_payload(29), 2), &C::version});
  list.push_back({"version_0", crafted_frame(PLIANT_TM_TYPE_ESTIMATE, 0, estimate_payload(29), 0), &C::version});
  // Payload length that does not match the type.
  list.push_back({"estimate_28", crafted_frame(1, 0, estimate_payload(28)), &C::bad_length});
  list.push_back({"estimate_30", crafted_frame(1, 0, estimate_payload(30)), &C::bad_length});
  list.push_back({"verdict_51", crafted_frame(2, 0, Bytes(51, 0)), &C::bad_length});
  list.push_back({"verdict_empty", crafted_frame(2, 0, Bytes{}), &C::bad_length});
  list.push_back({"particles_head_only_short", crafted_frame(3, 0, Bytes(11, 0)), &C::bad_length});
  list.push_back(
      {"particles_count_says_3_has_2", crafted_frame(3, 0, particles_payload(3, 10, 0, 3, 2)), &C::bad_length});
  list.push_back({"particles_extra_byte",
                  [] {
                    Bytes p = particles_payload(2, 10, 0, 1, 1);
                    p.push_back(0);
                    return crafted_frame(3, 0, p);
                  }(),
                  &C::bad_length});
  list.push_back({"counters_count_says_2_has_1", crafted_frame(4, 0, counters_payload(2, {1})), &C::bad_length});
  list.push_back({"counters_one_byte", crafted_frame(4, 0, Bytes{0}), &C::bad_length});
  // Fields out of range.
  list.push_back({"particles_dim_4", crafted_frame(3, 0, particles_payload(4, 10, 0, 1, 1)), &C::out_of_range});
  list.push_back({"particles_dim_1", crafted_frame(3, 0, particles_payload(1, 10, 0, 0, 0)), &C::out_of_range});
  list.push_back(
      {"particles_first_plus_count", crafted_frame(3, 0, particles_payload(3, 10, 8, 3, 3)), &C::out_of_range});
  list.push_back({"particles_status_3", crafted_frame(3, 0, particles_payload(2, 10, 0, 2, 2, 3)), &C::out_of_range});
  list.push_back({"verdict_3", crafted_frame(2, 0, verdict_payload(3, 0, 0, 0, 0)), &C::out_of_range});
  list.push_back({"reason_19", crafted_frame(2, 0, verdict_payload(0, 19, 0, 0, 0)), &C::out_of_range});
  list.push_back({"stop_action_2", crafted_frame(2, 0, verdict_payload(0, 0, 2, 0, 0)), &C::out_of_range});
  list.push_back({"fault_source_bit_5", crafted_frame(2, 0, verdict_payload(0, 0, 0, 0x20, 0)), &C::out_of_range});
  list.push_back({"reasons_bit_19", crafted_frame(2, 0, verdict_payload(0, 0, 0, 0, 1u << 19)), &C::out_of_range});
  list.push_back({"counters_duplicate_id", crafted_frame(4, 0, counters_payload(3, {1, 2, 1})), &C::out_of_range});
  // Unknown types with a good CRC.
  list.push_back({"type_0", crafted_frame(0, 0, Bytes(29, 1)), &C::unknown_type});
  list.push_back({"type_5", crafted_frame(5, 0, Bytes(3, 1)), &C::unknown_type});
  list.push_back({"type_255", crafted_frame(255, 0, Bytes{}), &C::unknown_type});
  return list;
}

TEST(telemetry_stream, EveryCorruptionCountedUnderItsReason) {
  using C = pliant_tm_decoder_counters_t;
  const std::uint32_t C::*const reasons[] = {&C::cobs_error,   &C::crc_mismatch, &C::oversize,
                                             &C::short_packet, &C::version,      &C::bad_length,
                                             &C::out_of_range, &C::unknown_type, &C::truncated};
  for (const Corruption& bad : corruptions()) {
    for (const std::vector<std::size_t>& pieces : {std::vector<std::size_t>{}, {1}, {5, 1, 333}}) {
      pliant_tm_encoder_t enc;
      pliant_tm_encoder_init(&enc, 0);
      Bytes stream = estimate_frame(enc, 1, sample_estimate());
      append(stream, bad.frame);
      append(stream, verdict_frame(enc, 2, sample_verdict()));
      pliant_tm_decoder_t dec;
      pliant_tm_decoder_init(&dec);
      const std::vector<Decoded> got = decode_all(dec, stream, pieces);
      ASSERT_EQ(got.size(), 2u) << bad.name;
      EXPECT_EQ(got[1].header.type, PLIANT_TM_TYPE_VERDICT) << bad.name;
      EXPECT_EQ(dec.counters.*bad.counter, 1u) << bad.name;
      for (const auto reason : reasons) {
        if (reason != bad.counter) {
          EXPECT_EQ(dec.counters.*reason, 0u) << bad.name;
        }
      }
      EXPECT_EQ(dec.counters.frames, 3u) << bad.name;
      expect_consistent(dec.counters);
    }
  }
}

TEST(telemetry_stream, SequenceGapsAndBackwardJumps) {
  // Packets with a good CRC carry a trustworthy sequence number, even when their payload is
  // unusable: seq 0, 1, 4 (2 missed), 5 (unknown type), 9 (3 missed), 3 (back), 4, 65535 (back
  // by more than half the space), 0.
  Bytes stream;
  const std::uint16_t seqs[] = {0, 1, 4, 5, 9, 3, 4, 65535, 0};
  for (std::uint16_t seq : seqs) {
    append(stream, seq == 5 ? crafted_frame(9, seq, Bytes{}) : crafted_frame(1, seq, estimate_payload(29)));
  }
  pliant_tm_decoder_t dec;
  pliant_tm_decoder_init(&dec);
  const std::vector<Decoded> got = decode_all(dec, stream);
  EXPECT_EQ(got.size(), 8u);
  EXPECT_EQ(dec.counters.unknown_type, 1u);
  EXPECT_EQ(dec.counters.seq_missed, 2u + 3u);
  // 9 -> 3 went back; 4 -> 65535 is 65531 ahead, i.e. 5 back.
  EXPECT_EQ(dec.counters.seq_backward, 2u);
}

TEST(telemetry_stream, EmitterRestartIsNotALoss) {
  // seq 40000 at 5 s, then the controller reboots: seq 0 at 0.1 ms. The sequence alone would
  // read as 25535 packets missed; the earlier stamp says restart.
  Bytes stream;
  const auto packet = [&](std::uint16_t seq, std::uint64_t stamp_us) {
    Bytes p = header_bytes(PLIANT_TM_TYPE_ESTIMATE, seq, stamp_us);
    append(p, estimate_payload(29));
    append(stream, frame_of(with_crc(p)));
  };
  packet(40000, 5'000'000);
  packet(40001, 5'000'100);
  packet(0, 100);
  packet(1, 200);
  packet(3, 300);
  pliant_tm_decoder_t dec;
  pliant_tm_decoder_init(&dec);
  EXPECT_EQ(decode_all(dec, stream).size(), 5u);
  EXPECT_EQ(dec.counters.seq_backward, 1u);
  EXPECT_EQ(dec.counters.seq_missed, 1u);
}

TEST(telemetry_stream, CrcBadPacketsDoNotMoveTheSequence) {
  pliant_tm_encoder_t enc;
  pliant_tm_encoder_init(&enc, 10);
  Bytes stream = estimate_frame(enc, 0, sample_estimate());             // 10
  Bytes broken = packet_of(estimate_frame(enc, 0, sample_estimate()));  // 11, CRC broken
  broken[2] = 200;                                                      // and its seq byte damaged
  append(stream, frame_of(broken));
  append(stream, estimate_frame(enc, 0, sample_estimate()));  // 12
  pliant_tm_decoder_t dec;
  pliant_tm_decoder_init(&dec);
  EXPECT_EQ(decode_all(dec, stream).size(), 2u);
  EXPECT_EQ(dec.counters.crc_mismatch, 1u);
  EXPECT_EQ(dec.counters.seq_missed, 1u);
  EXPECT_EQ(dec.counters.seq_backward, 0u);
}

TEST(telemetry_stream, TruncatedAtTheEnd) {
  const Sample s = sample_stream();
  for (std::size_t cut : {std::size_t{1}, std::size_t{20}, std::size_t{500}}) {
    Bytes stream(s.stream.begin(), s.stream.end() - static_cast<std::ptrdiff_t>(cut));
    pliant_tm_decoder_t dec;
    pliant_tm_decoder_init(&dec);
    const std::vector<Decoded> got = decode_all(dec, stream, {64});
    EXPECT_LT(got.size(), s.frames);
    EXPECT_EQ(drops(dec.counters), 0u) << "nothing is wrong until the stream ends";
    pliant_tm_decoder_finish(&dec);
    EXPECT_EQ(dec.counters.truncated, 1u) << cut;
    EXPECT_EQ(drops(dec.counters), 1u);
    expect_consistent(dec.counters);
    pliant_tm_decoder_finish(&dec);  // idempotent
    EXPECT_EQ(dec.counters.truncated, 1u);
  }
  // A stream ending on a delimiter is not truncated.
  pliant_tm_decoder_t dec;
  pliant_tm_decoder_init(&dec);
  decode_all(dec, s.stream);
  pliant_tm_decoder_finish(&dec);
  EXPECT_EQ(dec.counters.truncated, 0u);
  // After finish the decoder takes a new stream, sequence tracking restarted.
  const std::vector<Decoded> again = decode_all(dec, s.stream);
  EXPECT_EQ(again.size(), s.frames);
  EXPECT_EQ(dec.counters.seq_backward, 0u);
}

TEST(telemetry_stream, OversizeRunIsCountedOnceAndResynchronises) {
  pliant_tm_encoder_t enc;
  pliant_tm_encoder_init(&enc, 0);
  Bytes stream(5000, 0x5A);  // several frame lengths without a delimiter
  append(stream, Bytes{0});
  append(stream, estimate_frame(enc, 0, sample_estimate()));
  pliant_tm_decoder_t dec;
  pliant_tm_decoder_init(&dec);
  EXPECT_EQ(decode_all(dec, stream, {100}).size(), 1u);
  EXPECT_EQ(dec.counters.oversize, 1u);
  EXPECT_EQ(dec.counters.frames, 2u);
  // An oversize run cut by the end of the stream is not counted again as truncated.
  pliant_tm_decoder_init(&dec);
  const Bytes endless(3000, 0x5A);
  decode_all(dec, endless);
  pliant_tm_decoder_finish(&dec);
  EXPECT_EQ(dec.counters.oversize, 1u);
  EXPECT_EQ(dec.counters.truncated, 0u);
}

TEST(telemetry_stream, LargestFrameIsAccepted) {
  // The worst case: a 1024-byte packet without a zero byte is 1029 encoded bytes, 1030 with the
  // delimiter. Every valid message type has a zero byte somewhere (a count's high byte), so an
  // unknown type carries it: it must reach the type check, not be cut as oversize.
  Bytes packet;
  for (std::uint8_t fill = 1; fill != 0; ++fill) {
    packet = header_bytes(0x77, 0x0101, 0x0101010101010101ull);
    packet.resize(PLIANT_TM_MAX_PACKET - PLIANT_TM_CRC_SIZE, fill);
    packet = with_crc(packet);
    if (packet[packet.size() - 1] != 0 && packet[packet.size() - 2] != 0) break;
  }
  ASSERT_EQ(packet.size(), PLIANT_TM_MAX_PACKET);
  const Bytes frame = frame_of(packet);
  ASSERT_EQ(frame.size(), PLIANT_TM_MAX_FRAME);
  pliant_tm_decoder_t dec;
  pliant_tm_decoder_init(&dec);
  decode_all(dec, frame, {1});
  EXPECT_EQ(dec.counters.unknown_type, 1u);
  EXPECT_EQ(dec.counters.oversize, 0u);
  // The largest counters message (168 entries, a 1024-byte packet) decodes.
  pliant_tm_encoder_t enc;
  pliant_tm_encoder_init(&enc, 0);
  std::vector<pliant_tm_counter_t> counters;
  for (std::uint16_t i = 0; i < 168; ++i) counters.push_back({static_cast<std::uint16_t>(0x0101 + i), 0x01010101u});
  const Bytes largest = counters_frame(enc, 0, counters);
  EXPECT_EQ(packet_of(largest).size(), PLIANT_TM_MAX_PACKET);
  pliant_tm_decoder_init(&dec);
  const std::vector<Decoded> got = decode_all(dec, largest, {1});
  ASSERT_EQ(got.size(), 1u) << "drops " << drops(dec.counters);
  EXPECT_EQ(got[0].counters.size(), 168u);
}

TEST(telemetry_stream, NullArgumentsAreHarmless) {
  pliant_tm_decoder_t dec;
  pliant_tm_decoder_init(&dec);
  pliant_tm_message_t msg;
  std::size_t used = 99;
  const std::uint8_t byte = 0;
  EXPECT_EQ(pliant_tm_decoder_push(nullptr, &byte, 1, &used, &msg), 0);
  EXPECT_EQ(used, 0u);
  EXPECT_EQ(pliant_tm_decoder_push(&dec, nullptr, 5, &used, &msg), 0);
  EXPECT_EQ(pliant_tm_decoder_push(&dec, &byte, 1, nullptr, &msg), 0);
  EXPECT_EQ(pliant_tm_decoder_push(&dec, &byte, 1, &used, nullptr), 0);
  EXPECT_EQ(pliant_tm_decoder_push(&dec, nullptr, 0, &used, &msg), 0);
  pliant_tm_decoder_finish(nullptr);
  pliant_tm_decoder_init(nullptr);
  EXPECT_EQ(dec.counters.frames, 0u);
}

}  // namespace
}  // namespace pliant::telemetry_test
