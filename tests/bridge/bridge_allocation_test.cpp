// No-heap proof for pliant.h: every call, the real-time ones above all, makes zero heap
// allocations and frees, in 2D and 3D. tests/support/counting_allocator.cpp is compiled into
// this executable (see CMakeLists.txt), so operator new/delete and, on glibc without
// sanitizers, malloc/free are counted while an AllocationCounter is armed, including calls made
// from inside pliant_bridge and pliant_core. Inputs and outputs are prepared before arming;
// assertions run after disarming.
#include "support/counting_allocator.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "bridge_fixture.hpp"

namespace pliant::bridge_test {
namespace {

using test::AllocationCounter;
using test::AllocationCounts;

std::string describe(const AllocationCounts& c) {
  return "news=" + std::to_string(c.news) + " deletes=" + std::to_string(c.deletes) +
         " mallocs=" + std::to_string(c.mallocs) + " frees=" + std::to_string(c.frees) +
         (test::malloc_interposed() ? "" : " [malloc not interposed]");
}

bool counter_sees_new() {
  AllocationCounts counts;
  {
    AllocationCounter counter;
    int* volatile probe = new int(3);
    delete probe;
    counts = counter.stop();
  }
  return counts.news == 1 && counts.deletes == 1;
}

class BridgeAllocation : public ::testing::TestWithParam<std::uint32_t> {
 protected:
  void SetUp() override {
    if (!counter_sees_new()) GTEST_SKIP() << "another allocator (e.g. valgrind) owns the heap";
  }
};

TEST_P(BridgeAllocation, NoCallTouchesTheHeap) {
  const std::uint32_t dim = GetParam();
  LatticeObject object(dim, dim == 2 ? 8 : 4, 4, 3);
  object.drive_jaws();
  const pliant_config_t config = object.config();
  std::size_t bytes = 0;
  ASSERT_EQ(pliant_workspace_size(&config, &bytes), PLIANT_OK);
  std::vector<unsigned char> block(bytes);
  std::vector<float> frame = object.rest;
  std::vector<float> confidence(object.count(), 0.9f);
  std::vector<float> targets(object.drivable.size() * dim);
  for (std::size_t k = 0; k < object.drivable.size(); ++k) {
    for (std::uint32_t d = 0; d < dim; ++d)
      targets[k * dim + d] = object.rest[static_cast<std::size_t>(object.drivable[k]) * dim + d];
  }
  std::vector<float> tracked(object.rest.size());
  std::vector<std::uint8_t> status(object.count());
  pliant_estimate_t estimate;
  pliant_deformation_t deformation;
  pliant_counters_t counters;
  pliant_info_t info;
  pliant_verdict_t verdict;
  std::vector<std::uint8_t> telemetry(64 * 1024);
  std::size_t telemetry_bytes = 0;
  pliant_t* p = nullptr;
  const std::uint32_t contacts = static_cast<std::uint32_t>(object.drivable.size());

  // Init itself (not real-time) is heap-free too: everything lives in the block.
  AllocationCounts init_counts;
  pliant_status_t init_status = PLIANT_ERROR_INTERNAL;
  {
    AllocationCounter counter;
    std::size_t again = 0;
    (void)pliant_workspace_size(&config, &again);
    init_status = pliant_init(block.data(), block.size(), &config, &p);
    init_counts = counter.stop();
  }
  ASSERT_EQ(init_status, PLIANT_OK);
  EXPECT_EQ(init_counts.total(), 0u) << "init: " << describe(init_counts);

  // 60 frames of a squeeze with 1 kHz-style guard cycles between them, all armed.
  pliant_status_t worst = PLIANT_OK;
  auto note = [&worst](pliant_status_t s) {
    if (PLIANT_IS_ERROR(s)) worst = s;
  };
  AllocationCounts counts;
  {
    AllocationCounter counter;
    double now = 0;
    for (int f = 0; f < 60; ++f) {
      for (std::size_t i = 0; i < frame.size(); i += dim)
        frame[i] = object.rest[i] * (1.0f - 0.001f * static_cast<float>(f));
      note(pliant_push_observations(p, now, frame.data(), confidence.data()));
      note(pliant_push_tool_contact(p, object.drivable.data(), targets.data(), f > 10 ? contacts : 0u));
      note(pliant_step_tracker(p, 1.0 / 30));
      note(pliant_update_estimate(p));
      note(pliant_get_tracked(p, tracked.data(), status.data(), object.count(), nullptr));
      note(pliant_get_estimate(p, &estimate));
      note(pliant_get_deformation(p, &deformation));
      for (int c = 0; c < 33; ++c, now += 0.001) {
        pliant_guard_input_t in = fresh_input(now, 0.03 - 0.0001 * f, 0.1 * f);
        note(pliant_guard_update(p, &in, &verdict));
      }
      note(pliant_get_counters(p, &counters));
      note(pliant_telemetry_bytes(p, PLIANT_TELEMETRY_ALL, &telemetry_bytes));
      note(pliant_emit_telemetry(p, PLIANT_TELEMETRY_ALL, static_cast<std::uint64_t>(now * 1e6), telemetry.data(),
                                 telemetry.size(), &telemetry_bytes));
    }
    note(pliant_acknowledge_stop(p));
    note(pliant_reset_grasp_guard(p));
    note(pliant_reset_grasp(p));
    note(pliant_get_info(p, &info));
    // Refused calls are heap-free as well.
    (void)pliant_step_tracker(p, -1.0);
    (void)pliant_push_observations(p, 0.0, frame.data(), nullptr);
    (void)pliant_guard_update(p, nullptr, &verdict);
    std::size_t refused_bytes = 0;
    (void)pliant_emit_telemetry(p, PLIANT_TELEMETRY_ALL, 0, telemetry.data(), 1, &refused_bytes);
    counts = counter.stop();
  }
  EXPECT_EQ(worst, PLIANT_OK) << pliant_status_name(worst);
  EXPECT_EQ(counts.total(), 0u) << describe(counts);
  EXPECT_EQ(counters.tracker_frames, 60u);
  EXPECT_EQ(counters.guard_cycles, 60u * 33u);
  EXPECT_GT(telemetry_bytes, 0u);
}

INSTANTIATE_TEST_SUITE_P(Dims, BridgeAllocation, ::testing::Values(2u, 3u),
                         [](const ::testing::TestParamInfo<std::uint32_t>& dims) {
                           return std::to_string(dims.param) + "d";
                         });

}  // namespace
}  // namespace pliant::bridge_test
