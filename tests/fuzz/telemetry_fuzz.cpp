// libFuzzer target over the telemetry streaming decoder (firmware-bridge/include/pliant_telemetry.h).
//
// Input: byte 0 seeds how the rest is cut into pieces (1 .. 64 bytes, or everything at once);
// bytes 1.. are the stream. For each input the decoder must never read or write out of bounds
// (ASan), every message it delivers must satisfy the documented ranges, re-encoding a message
// and decoding it again must give the same fields bit for bit, and every frame must end up as
// exactly one message or one counted drop. COBS encode/decode of the raw bytes must round-trip.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "pliant_telemetry.h"

namespace {

void check(bool condition) {
  if (!condition) std::abort();
}

bool same(const void* a, const void* b, std::size_t size) { return std::memcmp(a, b, size) == 0; }

// The one message a frame decodes to (or aborts).
pliant_tm_message_t decode_frame(pliant_tm_decoder_t& decoder, const std::uint8_t* frame, std::size_t size) {
  pliant_tm_decoder_init(&decoder);
  pliant_tm_message_t message;
  std::size_t used = 0;
  check(pliant_tm_decoder_push(&decoder, frame, size, &used, &message) == 1);
  check(used == size);
  return message;
}

void check_and_reencode(const pliant_tm_message_t& m, const pliant_tm_decoder_t& owner) {
  static pliant_tm_decoder_t again;
  static std::uint8_t frame[PLIANT_TM_MAX_FRAME];
  static std::vector<float> positions(65535u * 3u);
  static std::vector<std::uint8_t> status(65535u);
  check(m.header.version == PLIANT_TM_VERSION);
  pliant_tm_encoder_t encoder;
  pliant_tm_encoder_init(&encoder, m.header.seq);
  std::int32_t size = 0;
  const std::uint8_t* const buffer_end = owner.frame + sizeof owner.frame;
  switch (m.header.type) {
    case PLIANT_TM_TYPE_ESTIMATE: {
      size = pliant_tm_encode_estimate(&encoder, m.header.stamp_us, &m.body.estimate, frame, sizeof frame);
      check(size == 45);
      const pliant_tm_estimate_t back = decode_frame(again, frame, static_cast<std::size_t>(size)).body.estimate;
      const pliant_tm_estimate_t& e = m.body.estimate;
      check(same(&back.msm_beta, &e.msm_beta, 8) && same(&back.msm_beta_std, &e.msm_beta_std, 8) &&
            same(&back.rms, &e.rms, 8) && back.frames == e.frames && back.flags == e.flags);
      break;
    }
    case PLIANT_TM_TYPE_VERDICT: {
      const pliant_tm_verdict_t& v = m.body.verdict;
      check(v.verdict < PLIANT_TM_VERDICT_COUNT && v.reason < PLIANT_TM_REASON_COUNT &&
            v.stop_action < PLIANT_TM_STOP_ACTION_COUNT && (v.fault_sources >> PLIANT_TM_SOURCE_COUNT) == 0 &&
            (v.reasons >> PLIANT_TM_REASON_COUNT) == 0);
      size = pliant_tm_encode_verdict(&encoder, m.header.stamp_us, &v, frame, sizeof frame);
      check(size == 68);
      const pliant_tm_verdict_t back = decode_frame(again, frame, static_cast<std::size_t>(size)).body.verdict;
      const float* a[10] = {&v.closure_m,        &v.force_n,        &v.strain,       &v.allowed_force_n,
                            &v.predicted_strain, &v.safe_closure_m, &v.safe_width_m, &v.predicted_force_n,
                            &v.beta_low,         &v.beta_high};
      const float* b[10] = {&back.closure_m,        &back.force_n,        &back.strain,       &back.allowed_force_n,
                            &back.predicted_strain, &back.safe_closure_m, &back.safe_width_m, &back.predicted_force_n,
                            &back.beta_low,         &back.beta_high};
      for (int i = 0; i < 10; ++i) check(same(a[i], b[i], 4));
      check(back.verdict == v.verdict && back.reason == v.reason && back.stop_action == v.stop_action &&
            back.fault_sources == v.fault_sources && back.reasons == v.reasons && back.flags == v.flags);
      break;
    }
    case PLIANT_TM_TYPE_PARTICLES: {
      const pliant_tm_particles_t& p = m.body.particles;
      check(p.dim == 2 || p.dim == 3);
      check(std::uint32_t{p.first} + p.count <= p.total);
      check(p.count <= PLIANT_TM_MAX_CHUNK_PARTICLES(p.dim));
      check(p.items >= owner.frame && p.items + std::size_t{p.count} * PLIANT_TM_PARTICLE_SIZE(p.dim) <= buffer_end);
      for (std::uint16_t i = 0; i < p.count; ++i) {
        float xyz[3];
        std::uint8_t s = 0;
        pliant_tm_particles_get(&p, i, xyz, &s);
        check(s <= PLIANT_TM_LOST);
        const std::size_t id = std::size_t{p.first} + i;
        std::memcpy(&positions[id * p.dim], xyz, p.dim * sizeof(float));
        status[id] = s;
      }
      const pliant_tm_particle_frame_t whole = {p.frame, p.dim, p.total, positions.data(), status.data()};
      size = pliant_tm_encode_particles(&encoder, m.header.stamp_us, &whole, p.first, p.count, frame, sizeof frame);
      check(size > 0);
      const pliant_tm_message_t back = decode_frame(again, frame, static_cast<std::size_t>(size));
      const pliant_tm_particles_t& q = back.body.particles;
      check(q.frame == p.frame && q.dim == p.dim && q.total == p.total && q.first == p.first && q.count == p.count);
      check(same(q.items, p.items, std::size_t{p.count} * PLIANT_TM_PARTICLE_SIZE(p.dim)));
      break;
    }
    case PLIANT_TM_TYPE_COUNTERS: {
      const pliant_tm_counters_t& c = m.body.counters;
      check(c.count <= PLIANT_TM_MAX_COUNTERS);
      check(c.items >= owner.frame && c.items + std::size_t{c.count} * PLIANT_TM_COUNTER_SIZE <= buffer_end);
      pliant_tm_counter_t entries[PLIANT_TM_MAX_COUNTERS];
      for (std::uint16_t i = 0; i < c.count; ++i) {
        entries[i] = pliant_tm_counters_get(&c, i);
        (void)pliant_tm_counter_name(entries[i].id);
      }
      size = pliant_tm_encode_counters(&encoder, m.header.stamp_us, entries, c.count, frame, sizeof frame);
      check(size > 0);  // ids are unique: the decoder checked
      const pliant_tm_counters_t back = decode_frame(again, frame, static_cast<std::size_t>(size)).body.counters;
      check(back.count == c.count && same(back.items, c.items, std::size_t{c.count} * PLIANT_TM_COUNTER_SIZE));
      break;
    }
    default: check(false);
  }
  check(static_cast<std::size_t>(size) <= PLIANT_TM_MAX_FRAME);
}

void cobs_round_trip(const std::uint8_t* data, std::size_t size) {
  static std::vector<std::uint8_t> encoded;
  static std::vector<std::uint8_t> decoded;
  encoded.resize(size + size / 254 + 2);
  const std::int32_t n = pliant_tm_cobs_encode(data, size, encoded.data(), encoded.size());
  check(n > 0 && static_cast<std::size_t>(n) <= (size == 0 ? 1 : size + (size + 253) / 254));
  for (std::int32_t i = 0; i < n; ++i) check(encoded[static_cast<std::size_t>(i)] != 0);
  decoded.resize(static_cast<std::size_t>(n));
  const std::int32_t m =
      pliant_tm_cobs_decode(encoded.data(), static_cast<std::size_t>(n), decoded.data(), decoded.size());
  check(m == static_cast<std::int32_t>(size));
  check(size == 0 || std::memcmp(decoded.data(), data, size) == 0);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  std::uint32_t state = data[0] * 2654435761u + 1u;
  const bool whole = data[0] == 0;
  ++data;
  --size;
  if (size <= 4096) cobs_round_trip(data, size);

  static pliant_tm_decoder_t decoder;
  pliant_tm_decoder_init(&decoder);
  std::size_t at = 0;
  while (at < size) {
    state = state * 1664525u + 1013904223u;
    std::size_t piece = whole ? size - at : 1 + (state >> 24) % 64;
    if (piece > size - at) piece = size - at;
    std::size_t offset = 0;
    while (offset < piece) {
      pliant_tm_message_t message;
      std::size_t used = 0;
      const int got = pliant_tm_decoder_push(&decoder, data + at + offset, piece - offset, &used, &message);
      check(used <= piece - offset);
      check(got == 1 || used == piece - offset);
      if (got == 1) check_and_reencode(message, decoder);
      offset += used;
    }
    at += piece;
  }
  pliant_tm_decoder_finish(&decoder);
  const pliant_tm_decoder_counters_t& c = decoder.counters;
  const std::uint64_t accounted = std::uint64_t{c.messages} + c.cobs_error + c.crc_mismatch + c.oversize +
                                  c.short_packet + c.version + c.bad_length + c.out_of_range + c.unknown_type +
                                  c.truncated;
  check(accounted == c.frames);
  return 0;
}
