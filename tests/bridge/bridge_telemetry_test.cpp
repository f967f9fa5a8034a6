// pliant_emit_telemetry: what it emits decodes (with the codec's own decoder) to exactly the
// instance's results; short buffers write nothing and are counted; sequence numbers run on.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "bridge_fixture.hpp"
#include "pliant_telemetry.h"

namespace pliant::bridge_test {
namespace {

bool same_float(double a, float b) { return (std::isnan(a) && std::isnan(b)) || static_cast<float>(a) == b; }

struct Decoded {
  std::vector<pliant_tm_message_t> messages;
  std::vector<float> positions;  // reassembled particles
  std::vector<std::uint8_t> status;
  std::vector<std::uint16_t> first_ids;
  std::vector<pliant_tm_counter_t> counters;
  pliant_tm_decoder_counters_t decoder{};
};

Decoded decode(const std::vector<std::uint8_t>& bytes, std::uint32_t particles, std::uint32_t dim,
               pliant_tm_decoder_t& decoder) {
  Decoded out;
  out.positions.assign(static_cast<std::size_t>(particles) * dim, std::nanf(""));
  out.status.assign(particles, 0xff);
  const std::uint8_t* data = bytes.data();
  std::size_t size = bytes.size();
  while (size > 0) {
    pliant_tm_message_t message;
    std::size_t used = 0;
    if (pliant_tm_decoder_push(&decoder, data, size, &used, &message) != 0) {
      out.messages.push_back(message);
      if (message.header.type == PLIANT_TM_TYPE_PARTICLES) {
        const pliant_tm_particles_t& chunk = message.body.particles;
        out.first_ids.push_back(chunk.first);
        for (std::uint16_t i = 0; i < chunk.count; ++i) {
          float position[3];
          std::uint8_t status = 0;
          pliant_tm_particles_get(&chunk, i, position, &status);
          const std::size_t id = static_cast<std::size_t>(chunk.first) + i;
          for (std::uint32_t d = 0; d < dim; ++d) out.positions[id * dim + d] = position[d];
          out.status[id] = status;
        }
      } else if (message.header.type == PLIANT_TM_TYPE_COUNTERS) {
        for (std::uint16_t i = 0; i < message.body.counters.count; ++i) {
          out.counters.push_back(pliant_tm_counters_get(&message.body.counters, i));
        }
      }
    }
    data += used;
    size -= used;
  }
  out.decoder = decoder.counters;
  return out;
}

class BridgeTelemetry : public ::testing::TestWithParam<std::uint32_t> {};

TEST_P(BridgeTelemetry, EmitsWhatTheInstanceHolds) {
  const std::uint32_t dim = GetParam();
  // Large enough that the particles need several chunks (76 per packet in 3D, 110 in 2D).
  LatticeObject object(dim, dim == 2 ? 16 : 6, dim == 2 ? 10 : 5, 4);
  object.drive_jaws();
  pliant_config_t config = object.config();
  config.guard.prediction_beta_points = 3;
  config.guard.prediction_closure_points = 4;
  Instance instance(config);
  ASSERT_EQ(instance.status, PLIANT_OK) << pliant_status_name(instance.status);
  pliant_t* p = instance.pliant;
  const std::uint32_t n = object.count();

  // Before any guard cycle there is no verdict to send.
  std::size_t bytes = 0;
  ASSERT_EQ(pliant_telemetry_bytes(p, PLIANT_TELEMETRY_VERDICT, &bytes), PLIANT_OK);
  EXPECT_EQ(bytes, 0u);

  std::vector<float> frame = object.rest;
  for (std::size_t i = 0; i < frame.size(); i += dim) frame[i] *= 0.98f;
  frame[dim * 3] = std::nanf("");  // one particle unobserved: status predicted
  ASSERT_EQ(pliant_push_observations(p, 0.0, frame.data(), nullptr), PLIANT_OK);
  ASSERT_EQ(pliant_step_tracker(p, 1.0 / 30), PLIANT_OK);
  ASSERT_EQ(pliant_update_estimate(p), PLIANT_OK);
  pliant_verdict_t verdict;
  const pliant_guard_input_t in = fresh_input(0.001, 0.2, 0.0);
  ASSERT_EQ(pliant_guard_update(p, &in, &verdict), PLIANT_OK);
  ASSERT_EQ(pliant_step_tracker(p, -1.0), PLIANT_ERROR_INVALID_ARGUMENT);  // one rejected call

  ASSERT_EQ(pliant_telemetry_bytes(p, PLIANT_TELEMETRY_ALL, &bytes), PLIANT_OK);
  std::vector<std::uint8_t> buffer(bytes + 16, 0xee);
  std::size_t written = 0;
  pliant_counters_t before = instance.counters();
  ASSERT_EQ(pliant_emit_telemetry(p, PLIANT_TELEMETRY_ALL, 123456789u, buffer.data(), bytes, &written), PLIANT_OK);
  ASSERT_GT(written, 0u);
  ASSERT_LE(written, bytes);
  EXPECT_EQ(buffer[bytes], 0xee) << "wrote past the capacity";
  buffer.resize(written);

  pliant_tm_decoder_t decoder;
  pliant_tm_decoder_init(&decoder);
  const Decoded d = decode(buffer, n, dim, decoder);
  const std::uint32_t chunks =
      (n + pliant_tm_particles_per_chunk(static_cast<std::uint8_t>(dim), PLIANT_TM_MAX_FRAME) - 1) /
      pliant_tm_particles_per_chunk(static_cast<std::uint8_t>(dim), PLIANT_TM_MAX_FRAME);
  ASSERT_GE(chunks, 2u);
  ASSERT_EQ(d.messages.size(), 3u + chunks);
  EXPECT_EQ(d.decoder.messages, 3u + chunks);
  EXPECT_EQ(d.decoder.frames, d.decoder.messages) << "every frame decoded";
  for (std::size_t k = 0; k < d.messages.size(); ++k) {
    EXPECT_EQ(d.messages[k].header.seq, static_cast<std::uint16_t>(k));
    EXPECT_EQ(d.messages[k].header.stamp_us, 123456789u);
  }
  EXPECT_EQ(d.messages.front().header.type, PLIANT_TM_TYPE_ESTIMATE);
  EXPECT_EQ(d.messages[1].header.type, PLIANT_TM_TYPE_VERDICT);
  EXPECT_EQ(d.messages.back().header.type, PLIANT_TM_TYPE_COUNTERS);

  pliant_estimate_t estimate;
  ASSERT_EQ(pliant_get_estimate(p, &estimate), PLIANT_OK);
  const pliant_tm_estimate_t& e = d.messages.front().body.estimate;
  EXPECT_EQ(e.msm_beta, estimate.msm_beta);
  EXPECT_EQ(e.msm_beta_std, estimate.msm_beta_std);
  EXPECT_EQ(e.rms, estimate.rms);
  EXPECT_EQ(e.frames, estimate.frames);
  EXPECT_EQ((e.flags & PLIANT_TM_ESTIMATE_VALID) != 0, estimate.valid);

  const pliant_tm_verdict_t& v = d.messages[1].body.verdict;
  EXPECT_EQ(v.verdict, verdict.verdict);
  EXPECT_EQ(v.reason, verdict.reason);
  EXPECT_EQ(v.reasons, verdict.reasons);
  EXPECT_EQ(v.fault_sources, verdict.fault_sources);
  EXPECT_EQ((v.flags & PLIANT_TM_VERDICT_IN_CONTACT) != 0, verdict.in_contact);
  EXPECT_TRUE(same_float(verdict.safe_width_m, v.safe_width_m));
  EXPECT_TRUE(same_float(verdict.allowed_force_n, v.allowed_force_n));
  EXPECT_TRUE(same_float(verdict.beta_high, v.beta_high));

  std::vector<float> tracked(static_cast<std::size_t>(n) * dim);
  std::vector<std::uint8_t> status(n);
  std::uint32_t frame_index = 0;
  ASSERT_EQ(pliant_get_tracked(p, tracked.data(), status.data(), n, &frame_index), PLIANT_OK);
  EXPECT_EQ(d.messages[2].body.particles.frame, frame_index);
  EXPECT_EQ(d.messages[2].body.particles.total, n);
  EXPECT_EQ(d.positions, tracked);
  EXPECT_EQ(d.status, status);
  EXPECT_EQ(status[3], PLIANT_TRACK_PREDICTED);

  ASSERT_EQ(d.counters.size(), static_cast<std::size_t>(PLIANT_COUNTER_ID_COUNT));
  for (const pliant_tm_counter_t& counter : d.counters) {
    std::uint32_t value = 0;
    ASSERT_EQ(pliant_counter_by_id(&before, counter.id, &value), PLIANT_OK);
    EXPECT_EQ(counter.value, value) << pliant_tm_counter_name(counter.id);
  }
  EXPECT_EQ(before.calls_rejected, 1u);

  // Too small: nothing written, every packet counted as not sent, no sequence number used.
  std::vector<std::uint8_t> small(bytes, 0xee);
  EXPECT_EQ(pliant_emit_telemetry(p, PLIANT_TELEMETRY_ALL, 2, small.data(), bytes - 1, &written),
            PLIANT_ERROR_MEMORY_TOO_SMALL);
  EXPECT_EQ(written, 0u);
  for (std::uint8_t byte : small) ASSERT_EQ(byte, 0xee);
  pliant_counters_t after = instance.counters();
  EXPECT_EQ(after.telemetry_not_sent, 3u + chunks);
  EXPECT_EQ(after.calls_rejected, 2u);
  EXPECT_EQ(after.last_rejected_call, PLIANT_CALL_EMIT_TELEMETRY);

  // The next emission continues the sequence without a gap.
  std::vector<std::uint8_t> one(PLIANT_TM_MAX_FRAME);
  ASSERT_EQ(pliant_emit_telemetry(p, PLIANT_TELEMETRY_COUNTERS, 3, one.data(), one.size(), &written), PLIANT_OK);
  one.resize(written);
  const Decoded next = decode(one, n, dim, decoder);
  ASSERT_EQ(next.messages.size(), 1u);
  EXPECT_EQ(next.messages[0].header.seq, static_cast<std::uint16_t>(3 + chunks));
  EXPECT_EQ(next.decoder.seq_missed, 0u);
  bool found = false;
  for (const pliant_tm_counter_t& counter : next.counters) {
    if (counter.id == PLIANT_COUNTER_TELEMETRY_NOT_SENT) {
      EXPECT_EQ(counter.value, 3u + chunks);
      found = true;
    }
  }
  EXPECT_TRUE(found);
}

INSTANTIATE_TEST_SUITE_P(Dims, BridgeTelemetry, ::testing::Values(2u, 3u),
                         [](const ::testing::TestParamInfo<std::uint32_t>& dims) {
                           return std::to_string(dims.param) + "d";
                         });

TEST(BridgeTelemetryArgs, RefusedAndCounted) {
  LatticeObject object(3, 4, 4, 3);
  object.drive_jaws();
  Instance instance(object.config());
  ASSERT_EQ(instance.status, PLIANT_OK);
  pliant_t* p = instance.pliant;
  std::vector<std::uint8_t> buffer(4096);
  std::size_t written = 99;
  std::size_t bytes = 0;
  EXPECT_EQ(pliant_emit_telemetry(nullptr, PLIANT_TELEMETRY_ALL, 0, buffer.data(), buffer.size(), &written),
            PLIANT_ERROR_NULL_ARGUMENT);
  EXPECT_EQ(written, 0u);
  EXPECT_EQ(pliant_emit_telemetry(p, PLIANT_TELEMETRY_ALL, 0, nullptr, buffer.size(), &written),
            PLIANT_ERROR_NULL_ARGUMENT);
  EXPECT_EQ(pliant_emit_telemetry(p, PLIANT_TELEMETRY_ALL, 0, buffer.data(), buffer.size(), nullptr),
            PLIANT_ERROR_NULL_ARGUMENT);
  EXPECT_EQ(pliant_emit_telemetry(p, 0x10, 0, buffer.data(), buffer.size(), &written), PLIANT_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(pliant_telemetry_bytes(p, 0x80, &bytes), PLIANT_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(pliant_telemetry_bytes(p, PLIANT_TELEMETRY_ALL, nullptr), PLIANT_ERROR_NULL_ARGUMENT);
  const pliant_counters_t counters = instance.counters();
  EXPECT_EQ(counters.calls_rejected, 5u);
  EXPECT_EQ(counters.telemetry_not_sent, 0u);
  // An empty mask is a valid request for nothing.
  EXPECT_EQ(pliant_emit_telemetry(p, 0, 0, buffer.data(), buffer.size(), &written), PLIANT_OK);
  EXPECT_EQ(written, 0u);
}

}  // namespace
}  // namespace pliant::bridge_test
