// Test helpers for the telemetry codec: frames of every message type, hand-built packets (to
// break a field while keeping the CRC right), and a decoder driver that keeps owned copies of
// what it decodes. Test-only: allocates and may throw.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "pliant_telemetry.h"

namespace pliant::telemetry_test {

using Bytes = std::vector<std::uint8_t>;

inline const float kNaNf = std::numeric_limits<float>::quiet_NaN();
inline const float kInff = std::numeric_limits<float>::infinity();
inline const double kNaN = std::numeric_limits<double>::quiet_NaN();
inline const double kInf = std::numeric_limits<double>::infinity();

inline void append(Bytes& to, const Bytes& from) { to.insert(to.end(), from.begin(), from.end()); }

// ---- encoding through the codec -----------------------------------------------------------

inline Bytes checked(std::int32_t length, const Bytes& buffer) {
  if (length <= 0) throw std::runtime_error("encoder failed: " + std::to_string(length));
  return Bytes(buffer.begin(), buffer.begin() + length);
}

inline Bytes estimate_frame(pliant_tm_encoder_t& enc, std::uint64_t stamp_us, const pliant_tm_estimate_t& m) {
  Bytes out(PLIANT_TM_MAX_FRAME);
  return checked(pliant_tm_encode_estimate(&enc, stamp_us, &m, out.data(), out.size()), out);
}

inline Bytes verdict_frame(pliant_tm_encoder_t& enc, std::uint64_t stamp_us, const pliant_tm_verdict_t& m) {
  Bytes out(PLIANT_TM_MAX_FRAME);
  return checked(pliant_tm_encode_verdict(&enc, stamp_us, &m, out.data(), out.size()), out);
}

inline Bytes counters_frame(pliant_tm_encoder_t& enc, std::uint64_t stamp_us,
                            const std::vector<pliant_tm_counter_t>& counters) {
  Bytes out(PLIANT_TM_MAX_FRAME);
  return checked(pliant_tm_encode_counters(&enc, stamp_us, counters.data(), static_cast<std::uint16_t>(counters.size()),
                                           out.data(), out.size()),
                 out);
}

/// A whole tracked frame, owned.
struct ParticleFrame {
  std::uint32_t frame = 0;
  std::uint8_t dim = 3;
  std::vector<float> positions;  // total * dim
  std::vector<std::uint8_t> status;
  std::uint16_t total() const { return static_cast<std::uint16_t>(status.size()); }
  pliant_tm_particle_frame_t view() const {
    return pliant_tm_particle_frame_t{frame, dim, total(), positions.data(), status.data()};
  }
};

/// `total` particles on a line, moved by `frame`; particle i has status i % 7 == 3 ? predicted,
/// i % 11 == 5 ? lost, else observed, unless `all_observed`.
inline ParticleFrame make_particle_frame(std::uint32_t frame, std::uint8_t dim, std::uint16_t total,
                                         bool all_observed = false) {
  ParticleFrame f;
  f.frame = frame;
  f.dim = dim;
  for (std::uint16_t i = 0; i < total; ++i) {
    for (std::uint8_t axis = 0; axis < dim; ++axis) {
      f.positions.push_back(0.01f * static_cast<float>(i) + 0.001f * static_cast<float>(axis) -
                            0.0005f * static_cast<float>(frame));
    }
    std::uint8_t status = PLIANT_TM_OBSERVED;
    if (!all_observed && i % 7 == 3) status = PLIANT_TM_PREDICTED;
    if (!all_observed && i % 11 == 5) status = PLIANT_TM_LOST;
    f.status.push_back(status);
  }
  return f;
}

/// Every chunk of a particle frame, in order, split as pliant_tm_particles_per_chunk says for
/// frames of at most `frame_capacity` bytes.
inline std::vector<Bytes> particle_chunks(pliant_tm_encoder_t& enc, std::uint64_t stamp_us, const ParticleFrame& f,
                                          std::size_t frame_capacity = PLIANT_TM_MAX_FRAME) {
  const std::uint16_t per_chunk = pliant_tm_particles_per_chunk(f.dim, frame_capacity);
  if (per_chunk == 0) throw std::runtime_error("no particle fits");
  const pliant_tm_particle_frame_t view = f.view();
  std::vector<Bytes> chunks;
  std::uint32_t first = 0;
  do {
    const auto count = static_cast<std::uint16_t>(std::min<std::uint32_t>(per_chunk, f.total() - first));
    Bytes out(frame_capacity);
    chunks.push_back(checked(pliant_tm_encode_particles(&enc, stamp_us, &view, static_cast<std::uint16_t>(first), count,
                                                        out.data(), out.size()),
                             out));
    first += count;
  } while (first < f.total());
  return chunks;
}

inline pliant_tm_estimate_t sample_estimate() {
  pliant_tm_estimate_t e{};
  e.msm_beta = 0.375;
  e.msm_beta_std = 0.0625;
  e.rms = 1.5e-4;
  e.frames = 123456;
  e.flags = PLIANT_TM_ESTIMATE_UNIQUE_MINIMUM | PLIANT_TM_ESTIMATE_VALID;
  return e;
}

inline pliant_tm_verdict_t sample_verdict() {
  pliant_tm_verdict_t v{};
  v.verdict = 1;
  v.reason = 14;  // force_limit
  v.stop_action = 1;
  v.fault_sources = 0x04;  // camera
  v.reasons = (1u << 14) | (1u << 12);
  v.flags = PLIANT_TM_VERDICT_IN_CONTACT;
  v.closure_m = 0.004f;
  v.force_n = 7.5f;
  v.strain = 0.05f;
  v.allowed_force_n = 7.0f;
  v.predicted_strain = 0.06f;
  v.safe_closure_m = 0.0035f;
  v.safe_width_m = 0.0415f;
  v.predicted_force_n = 6.9f;
  v.beta_low = 0.25f;
  v.beta_high = 0.5f;
  return v;
}

// ---- hand-built packets -------------------------------------------------------------------

inline void put_u16(Bytes& b, std::uint16_t v) {
  b.push_back(static_cast<std::uint8_t>(v & 0xFF));
  b.push_back(static_cast<std::uint8_t>(v >> 8));
}
inline void put_u32(Bytes& b, std::uint32_t v) {
  for (int s = 0; s < 32; s += 8) b.push_back(static_cast<std::uint8_t>((v >> s) & 0xFF));
}
inline void put_u64(Bytes& b, std::uint64_t v) {
  for (int s = 0; s < 64; s += 8) b.push_back(static_cast<std::uint8_t>((v >> s) & 0xFF));
}
inline void put_f32(Bytes& b, float v) {
  std::uint32_t bits = 0;
  std::memcpy(&bits, &v, sizeof bits);
  put_u32(b, bits);
}

/// Header bytes (12) of a packet.
inline Bytes header_bytes(std::uint8_t type, std::uint16_t seq, std::uint64_t stamp_us, std::uint8_t version = 1) {
  Bytes b{version, type};
  put_u16(b, seq);
  put_u64(b, stamp_us);
  return b;
}

/// packet + CRC trailer.
inline Bytes with_crc(Bytes packet) {
  const std::uint16_t crc = pliant_tm_crc16(packet.data(), packet.size());
  put_u16(packet, crc);
  return packet;
}

/// COBS(packet) + 0x00.
inline Bytes frame_of(const Bytes& packet) {
  Bytes out(packet.size() + packet.size() / 254 + 2);
  const std::int32_t n = pliant_tm_cobs_encode(packet.data(), packet.size(), out.data(), out.size());
  if (n < 0) throw std::runtime_error("cobs encode failed");
  out.resize(static_cast<std::size_t>(n));
  out.push_back(0);
  return out;
}

/// The packet inside one frame (COBS removed, delimiter dropped).
inline Bytes packet_of(const Bytes& frame) {
  if (frame.empty() || frame.back() != 0) throw std::runtime_error("not a frame");
  Bytes out(frame.size());
  const std::int32_t n = pliant_tm_cobs_decode(frame.data(), frame.size() - 1, out.data(), out.size());
  if (n < 0) throw std::runtime_error("cobs decode failed");
  out.resize(static_cast<std::size_t>(n));
  return out;
}

/// A frame with a correct CRC around header + payload.
inline Bytes crafted_frame(std::uint8_t type, std::uint16_t seq, const Bytes& payload, std::uint8_t version = 1,
                           std::uint64_t stamp_us = 1000) {
  Bytes packet = header_bytes(type, seq, stamp_us, version);
  append(packet, payload);
  return frame_of(with_crc(packet));
}

// ---- decoding -----------------------------------------------------------------------------

/// A decoded message with its variable payload copied out of the decoder.
struct Decoded {
  pliant_tm_header_t header{};
  pliant_tm_estimate_t estimate{};
  pliant_tm_verdict_t verdict{};
  pliant_tm_particles_t particles{};  // items not valid: use positions/status
  std::vector<float> positions;       // count * 3 (z = 0 in 2D)
  std::vector<std::uint8_t> status;
  std::vector<pliant_tm_counter_t> counters;
};

inline Decoded own(const pliant_tm_message_t& m) {
  Decoded d;
  d.header = m.header;
  switch (m.header.type) {
    case PLIANT_TM_TYPE_ESTIMATE: d.estimate = m.body.estimate; break;
    case PLIANT_TM_TYPE_VERDICT: d.verdict = m.body.verdict; break;
    case PLIANT_TM_TYPE_PARTICLES:
      d.particles = m.body.particles;
      for (std::uint16_t i = 0; i < m.body.particles.count; ++i) {
        float p[3];
        std::uint8_t s = 0;
        pliant_tm_particles_get(&m.body.particles, i, p, &s);
        d.positions.insert(d.positions.end(), p, p + 3);
        d.status.push_back(s);
      }
      d.particles.items = nullptr;
      break;
    case PLIANT_TM_TYPE_COUNTERS:
      for (std::uint16_t i = 0; i < m.body.counters.count; ++i)
        d.counters.push_back(pliant_tm_counters_get(&m.body.counters, i));
      break;
    default: break;
  }
  return d;
}

/// Feeds `stream` in pieces of the given sizes (cycled; the last piece takes the rest) and
/// returns every message.
inline std::vector<Decoded> decode_all(pliant_tm_decoder_t& dec, const Bytes& stream,
                                       const std::vector<std::size_t>& pieces = {}) {
  std::vector<Decoded> out;
  std::size_t at = 0;
  std::size_t k = 0;
  while (at < stream.size()) {
    std::size_t piece = pieces.empty() ? stream.size() - at : pieces[k++ % pieces.size()];
    piece = std::max<std::size_t>(1, std::min(piece, stream.size() - at));
    const std::uint8_t* data = stream.data() + at;
    std::size_t left = piece;
    while (left > 0) {
      pliant_tm_message_t msg;
      std::size_t used = 0;
      const int got = pliant_tm_decoder_push(&dec, data, left, &used, &msg);
      if (used > left) throw std::runtime_error("decoder consumed more than given");
      if (got == 1) out.push_back(own(msg));
      if (got != 1 && used != left) throw std::runtime_error("decoder stopped without a message");
      data += used;
      left -= used;
    }
    at += piece;
  }
  return out;
}

/// Bit-exact equality of reals (NaN payloads included).
inline bool same_bits(float a, float b) { return std::memcmp(&a, &b, sizeof a) == 0; }
inline bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

/// Sum of the drop counters.
inline std::uint32_t drops(const pliant_tm_decoder_counters_t& c) {
  return c.cobs_error + c.crc_mismatch + c.oversize + c.short_packet + c.version + c.bad_length + c.out_of_range +
         c.unknown_type + c.truncated;
}

}  // namespace pliant::telemetry_test
