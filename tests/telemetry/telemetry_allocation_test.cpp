// No-heap proof for the telemetry codec: encoding every message type and decoding a stream
// (with garbage, corruption and truncation) make zero heap allocations and frees. The counting
// allocator (tests/support/counting_allocator.cpp) replaces operator new/delete and, on glibc
// without sanitizers, malloc and free, for this executable. Everything is prepared before the
// counter is armed; assertions run after it is disarmed.
#include "support/counting_allocator.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <vector>

#include "pliant_telemetry.h"
#include "telemetry/telemetry_test_support.hpp"

namespace pliant::telemetry_test {
namespace {

using test::AllocationCounter;
using test::AllocationCounts;

std::string describe(const AllocationCounts& c) {
  return "news=" + std::to_string(c.news) + " deletes=" + std::to_string(c.deletes) +
         " mallocs=" + std::to_string(c.mallocs) + " frees=" + std::to_string(c.frees) +
         (test::malloc_interposed() ? "" : " [malloc not interposed in this build]");
}

bool counter_sees_allocations() {
  AllocationCounter counter;
  int* volatile probe = new int(3);
  delete probe;
  void* volatile block = std::malloc(16);
  std::free(block);
  const AllocationCounts counts = counter.stop();
  return counts.news == 1 && counts.deletes == 1 && (!test::malloc_interposed() || counts.mallocs == 1);
}

TEST(telemetry_allocation, EncodeAndDecodeNeverTouchTheHeap) {
  ASSERT_TRUE(counter_sees_allocations()) << "the counting allocator is not in charge (valgrind?)";

  // Prepared before arming: inputs, output buffers, decoder, a corrupted stream.
  const pliant_tm_estimate_t estimate = sample_estimate();
  const pliant_tm_verdict_t verdict = sample_verdict();
  const ParticleFrame particles = make_particle_frame(3, 3, 200);
  const pliant_tm_particle_frame_t view = particles.view();
  std::vector<pliant_tm_counter_t> counters;
  for (std::uint16_t id = 1; id <= 15; ++id) counters.push_back({id, 1000u * id});
  Bytes stream(64 * 1024);
  Bytes garbage(3000, 0x5A);
  garbage.push_back(0);
  garbage.push_back(0x09);
  garbage.push_back(0x00);
  pliant_tm_decoder_t decoder;
  pliant_tm_decoder_init(&decoder);
  pliant_tm_encoder_t encoder;
  pliant_tm_encoder_init(&encoder, 0);
  std::size_t length = 0;
  std::size_t messages = 0;
  std::int32_t worst = 1;
  std::uint32_t checksum = 0;

  AllocationCounter counter;
  // Encode: garbage, then 20 rounds of every type, straight into one stream buffer.
  for (std::uint8_t b : garbage) stream[length++] = b;
  for (int round = 0; round < 20; ++round) {
    const std::uint64_t stamp = static_cast<std::uint64_t>(round) * 1000u;
    std::int32_t n = pliant_tm_encode_estimate(&encoder, stamp, &estimate, &stream[length], stream.size() - length);
    worst = n < worst ? n : worst;
    length += n > 0 ? static_cast<std::size_t>(n) : 0u;
    n = pliant_tm_encode_verdict(&encoder, stamp, &verdict, &stream[length], stream.size() - length);
    worst = n < worst ? n : worst;
    length += n > 0 ? static_cast<std::size_t>(n) : 0u;
    const std::uint16_t per = pliant_tm_particles_per_chunk(view.dim, 512);
    for (std::uint16_t first = 0; first < view.total; first = static_cast<std::uint16_t>(first + per)) {
      const std::uint16_t count = static_cast<std::uint16_t>(view.total - first < per ? view.total - first : per);
      n = pliant_tm_encode_particles(&encoder, stamp, &view, first, count, &stream[length], 512);
      worst = n < worst ? n : worst;
      length += n > 0 ? static_cast<std::size_t>(n) : 0u;
    }
    n = pliant_tm_encode_counters(&encoder, stamp, counters.data(), static_cast<std::uint16_t>(counters.size()),
                                  &stream[length], stream.size() - length);
    worst = n < worst ? n : worst;
    length += n > 0 ? static_cast<std::size_t>(n) : 0u;
  }
  // Decode it all in 7-byte pieces, reading every payload, and end inside the last frame.
  const std::size_t cut = length - 1;
  for (std::size_t at = 0; at < cut;) {
    const std::size_t piece = cut - at < 7 ? cut - at : 7;
    std::size_t offset = 0;
    while (offset < piece) {
      pliant_tm_message_t message;
      std::size_t used = 0;
      if (pliant_tm_decoder_push(&decoder, &stream[at + offset], piece - offset, &used, &message)) {
        ++messages;
        if (message.header.type == PLIANT_TM_TYPE_PARTICLES) {
          for (std::uint16_t i = 0; i < message.body.particles.count; ++i) {
            float position[3];
            std::uint8_t status = 0;
            pliant_tm_particles_get(&message.body.particles, i, position, &status);
            checksum += status;
          }
        } else if (message.header.type == PLIANT_TM_TYPE_COUNTERS) {
          for (std::uint16_t i = 0; i < message.body.counters.count; ++i) {
            checksum += pliant_tm_counters_get(&message.body.counters, i).value;
            checksum += pliant_tm_counter_name(pliant_tm_counters_get(&message.body.counters, i).id) != nullptr;
          }
        }
      }
      offset += used;
    }
    at += piece;
  }
  pliant_tm_decoder_finish(&decoder);
  const AllocationCounts counts = counter.stop();

  EXPECT_EQ(counts.total(), 0u) << describe(counts);
  EXPECT_GT(worst, 0) << "every frame was encoded";
  // 20 rounds: estimate, verdict, 200 / 37 -> 6 particle chunks, counters = 9 per round; the
  // last (cut before its delimiter) is lost as truncated.
  EXPECT_EQ(pliant_tm_particles_per_chunk(3, 512), 37u);
  EXPECT_EQ(messages, 20u * 9u - 1u);
  EXPECT_EQ(decoder.counters.oversize, 1u);
  EXPECT_EQ(decoder.counters.cobs_error, 1u);
  EXPECT_EQ(decoder.counters.truncated, 1u);
  EXPECT_GT(checksum, 0u);
}

}  // namespace
}  // namespace pliant::telemetry_test
