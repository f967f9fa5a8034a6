// read() of the OpenCV camera in real-time file mode and device mode touches no heap: frames are
// decoded and converted by the decoder thread into the ring sized at configure, read() only picks
// a slot. The decoder is idle while counting (the whole clip is buffered, or the fake device has
// no permits), because the counting allocator counts every thread.
#include <gtest/gtest.h>

#include <cstdint>
#include <memory>

#include "opencv_test_media.hpp"
#include "pliant/drivers/opencv/opencv_camera.hpp"
#include "support/counting_allocator.hpp"
#include "support/temp_dir.hpp"

namespace pliant::drivers {
namespace {

using hal::HalStatus;

TEST(OpenCvAllocation, RealTimeFileReadsAreAllocationFree) {
  test_support::TempDir dir("pliant_opencv_alloc_");
  const std::string video = dir / "clip.avi";
  opencv_test::write_video(video, 6, 10.0);
  hal::ManualClock clock(1.0);
  OpenCvCameraConfig config;
  config.source = OpenCvSource::video_file;
  config.location = video;
  config.ring_frames = 8;  // holds the whole clip
  OpenCvCamera camera(clock, config);
  ASSERT_EQ(camera.configure(), HalStatus::ok) << camera.last_error();
  ASSERT_EQ(camera.start(), HalStatus::ok);
  ASSERT_TRUE(camera.wait_buffered(6, 10.0));

  hal::ColorFrame frame;
  int delivered = 0, empty = 0, other = 0;
  pliant::test::AllocationCounter counter;
  for (int step = 0; step < 80; ++step) {  // 0.8 s in 10 ms steps: every frame, many no_data, the end
    const HalStatus status = camera.read(frame);
    if (status == HalStatus::ok) {
      ++delivered;
    } else if (status == HalStatus::no_data) {
      ++empty;
    } else {
      ++other;
    }
    (void)camera.end_of_stream();
    (void)camera.stats();
    (void)clock.advance(0.01);
  }
  const pliant::test::AllocationCounts counts = counter.stop();
  EXPECT_EQ(counts.total(), 0u) << "news " << counts.news << " mallocs " << counts.mallocs;
  EXPECT_EQ(delivered, 6);
  EXPECT_EQ(empty, 74);
  EXPECT_EQ(other, 0);
  EXPECT_TRUE(camera.end_of_stream());
}

TEST(OpenCvAllocation, DeviceReadsAreAllocationFree) {
  auto script = std::make_shared<opencv_test::FakeScript>();
  script->permits = 1;
  hal::ManualClock clock(1.0);
  OpenCvCameraConfig config;
  config.source = OpenCvSource::v4l2_device;
  config.location = "fake";
  OpenCvCamera camera(clock, config, std::make_shared<opencv_test::FakeFactory>(script, true));
  ASSERT_EQ(camera.configure(), HalStatus::ok) << camera.last_error();
  ASSERT_EQ(camera.start(), HalStatus::ok);
  ASSERT_TRUE(opencv_test::emit_and_settle(*script, 3));

  hal::ColorFrame frame;
  pliant::test::AllocationCounter counter;
  const HalStatus first = camera.read(frame);
  const HalStatus second = camera.read(frame);
  const pliant::test::AllocationCounts counts = counter.stop();
  EXPECT_EQ(counts.total(), 0u);
  EXPECT_EQ(first, HalStatus::ok);
  EXPECT_EQ(second, HalStatus::no_data);
}

}  // namespace
}  // namespace pliant::drivers
