// read() of the libcamera camera, and the completion path (conversion, triple-buffer swap,
// requeue) in between, touch no heap.
#include <gtest/gtest.h>

#include <memory>

#include "fake_backend.hpp"
#include "pliant/drivers/libcamera/libcamera_camera.hpp"
#include "support/counting_allocator.hpp"

namespace pliant::drivers {
namespace {

using hal::HalStatus;
using libcamera_detail::CompletionStatus;

TEST(LibcameraAllocation, ReadsAndCompletionsAreAllocationFree) {
  libcamera_test::FakeBackendState state;
  state.setup.format = libcamera_detail::RawFormat::yuyv;
  state.setup.width = 64;
  state.setup.height = 48;
  state.setup.stride = 128;
  libcamera_test::make_buffers(state, 4, 128 * 48);
  hal::ManualClock clock(1.0);
  LibcameraCamera camera(clock, LibcameraCameraConfig{}, std::make_unique<libcamera_test::FakeBackend>(state));
  ASSERT_EQ(camera.configure(), HalStatus::ok);
  ASSERT_EQ(camera.start(), HalStatus::ok);
  hal::ColorFrame frame;
  int ok = 0, empty = 0;
  pliant::test::AllocationCounter counter;
  for (std::uint32_t k = 0; k < 40; ++k) {
    const int index = state.queued.front();
    libcamera_test::complete(state, index, k % 7 == 3 ? CompletionStatus::error : CompletionStatus::success, k);
    (camera.read(frame) == HalStatus::ok ? ok : empty) += 1;
    (camera.read(frame) == HalStatus::ok ? ok : empty) += 1;
    (void)camera.stats();
  }
  const pliant::test::AllocationCounts counts = counter.stop();
  EXPECT_EQ(counts.total(), 0u) << "news " << counts.news << " mallocs " << counts.mallocs;
  EXPECT_EQ(ok, 34);
  EXPECT_EQ(empty, 46);
}

}  // namespace
}  // namespace pliant::drivers
