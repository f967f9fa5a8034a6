// OpenCV camera as a live device: the device logic on a scripted fake source (newest frame wins,
// frames grabbed while inactive discarded, overruns, loss and reconnection paced by the injected
// clock, a backend that throws), configure's first-frame wait and wait_buffered on a ManualClock,
// absent V4L2 devices, and a live V4L2 test that skips without /dev/video*.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <system_error>
#include <thread>

#include "opencv_test_media.hpp"
#include "pliant/drivers/opencv/opencv_camera.hpp"

namespace pliant::drivers {
namespace {

using hal::HalStatus;
using hal::ManualClock;
using opencv_test::FakeFactory;
using opencv_test::FakeScript;

// Waits up to 10 s for `condition`.
template <typename Condition>
bool eventually(Condition condition) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (std::chrono::steady_clock::now() < deadline) {
    if (condition()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return condition();
}

class OpenCvFakeDevice : public ::testing::Test {
 protected:
  OpenCvFakeDevice() : script_(std::make_shared<FakeScript>()) {
    config_.source = OpenCvSource::v4l2_device;
    config_.location = "fake";
    config_.format = hal::PixelFormat::mono8;
    config_.reconnect_interval_s = 0.001;
  }
  // Configures with one permit for the sizing frame.
  std::unique_ptr<OpenCvCamera> configured() {
    script_->permits = 1;
    auto camera = std::make_unique<OpenCvCamera>(clock_, config_, std::make_shared<FakeFactory>(script_, true));
    EXPECT_EQ(camera->configure(), HalStatus::ok) << camera->last_error();
    return camera;
  }
  // Lets the fake yield `frames` frames and waits until the camera handled them all.
  void emit(int frames) { ASSERT_TRUE(opencv_test::emit_and_settle(*script_, frames)); }
  // Reads as a loop would, the clock advanced by `step_s` before each read (reopen attempts are
  // paced by read() on the clock), until `condition` holds; false after 10 s of real time.
  template <typename Condition>
  bool read_until(OpenCvCamera& camera, Condition condition, double step_s = 0.01) {
    return eventually([&] {
      (void)clock_.advance(step_s);
      hal::ColorFrame frame;
      (void)camera.read(frame);
      return condition();
    });
  }

  ManualClock clock_{20.0};
  OpenCvCameraConfig config_;
  std::shared_ptr<FakeScript> script_;
};

TEST_F(OpenCvFakeDevice, NewestFrameWinsAndIsStampedByItsAge) {
  auto camera = configured();
  EXPECT_EQ(camera->width(), 16);
  EXPECT_EQ(camera->height(), 8);
  ASSERT_EQ(camera->start(), HalStatus::ok);
  hal::ColorFrame frame;
  EXPECT_EQ(camera->read(frame), HalStatus::no_data);
  emit(3);  // the fake's frames 1..3 (0 sized the ring)
  ASSERT_EQ(camera->read(frame), HalStatus::ok);
  EXPECT_EQ(frame.header.sequence, 3u);
  EXPECT_EQ(frame.data[0], 3);
  EXPECT_EQ(frame.data[frame.height * frame.stride_bytes - 1], 3);
  EXPECT_EQ(frame.format, hal::PixelFormat::mono8);
  EXPECT_LE(frame.header.stamp_s, 20.0);
  EXPECT_GT(frame.header.stamp_s, 20.0 - 10.0);
  EXPECT_TRUE(std::isnan(camera->media_time_s()));
  EXPECT_EQ(camera->stats().skipped, 2u);
  EXPECT_EQ(camera->counters().dropped, 2u);
  EXPECT_EQ(camera->read(frame), HalStatus::no_data);
  emit(1);
  ASSERT_EQ(camera->read(frame), HalStatus::ok);
  EXPECT_EQ(frame.header.sequence, 4u);
  EXPECT_FALSE(camera->end_of_stream());  // devices never end
}

TEST_F(OpenCvFakeDevice, FramesGrabbedWhileInactiveAreDiscarded) {
  auto camera = configured();
  emit(2);  // grabbed before start: not numbered, not delivered
  ASSERT_EQ(camera->start(), HalStatus::ok);
  emit(1);
  hal::ColorFrame frame;
  ASSERT_EQ(camera->read(frame), HalStatus::ok);
  EXPECT_EQ(frame.header.sequence, 1u);
  EXPECT_EQ(frame.data[0], 3);
  ASSERT_EQ(camera->stop(), HalStatus::ok);
  emit(2);  // while stopped
  ASSERT_EQ(camera->start(), HalStatus::ok);
  EXPECT_EQ(camera->read(frame), HalStatus::no_data);
  emit(1);
  ASSERT_EQ(camera->read(frame), HalStatus::ok);
  EXPECT_EQ(frame.header.sequence, 2u);  // numbering continues across stop/start
  EXPECT_EQ(camera->counters().dropped, 0u);
  EXPECT_EQ(camera->stats().decoded, 2u);
}

TEST_F(OpenCvFakeDevice, FullRingCountsOverruns) {
  config_.ring_frames = 2;
  auto camera = configured();
  ASSERT_EQ(camera->start(), HalStatus::ok);
  emit(5);  // 1 and 2 fill the ring, 3..5 overrun
  EXPECT_EQ(camera->stats().overruns, 3u);
  hal::ColorFrame frame;
  ASSERT_EQ(camera->read(frame), HalStatus::ok);
  EXPECT_EQ(frame.header.sequence, 2u);
  emit(1);
  ASSERT_EQ(camera->read(frame), HalStatus::ok);
  EXPECT_EQ(frame.header.sequence, 6u);
  const OpenCvCameraStats stats = camera->stats();
  EXPECT_EQ(stats.skipped, 1u);
  EXPECT_EQ(camera->counters().dropped, stats.skipped + stats.overruns);
}

TEST_F(OpenCvFakeDevice, LossIsReportedAndTheDeviceIsReopened) {
  auto camera = configured();
  ASSERT_EQ(camera->start(), HalStatus::ok);
  emit(1);
  hal::ColorFrame frame;
  ASSERT_EQ(camera->read(frame), HalStatus::ok);

  script_->failing_opens = 1000000;  // away until the test lets it back
  script_->fail_next = true;
  ASSERT_TRUE(eventually([&] { return camera->stats().device_lost; }));
  EXPECT_EQ(camera->read(frame), HalStatus::disconnected);
  EXPECT_EQ(camera->read(frame), HalStatus::disconnected);
  EXPECT_EQ(camera->counters().disconnects, 1u);
  EXPECT_EQ(camera->counters().disconnected, 2u);

  // Failed attempts go on at the reconnect interval until the device is back.
  ASSERT_TRUE(read_until(*camera, [&] { return camera->stats().reconnect_attempts >= 2; }));
  EXPECT_EQ(camera->stats().reopened, 0u);
  script_->failing_opens = 0;
  ASSERT_TRUE(read_until(*camera, [&] { return camera->stats().reopened == 1; }));
  EXPECT_FALSE(camera->stats().device_lost);
  EXPECT_EQ(static_cast<std::uint64_t>(script_->opens.load()), 1 + camera->stats().reconnect_attempts);
  emit(1);
  ASSERT_EQ(camera->read(frame), HalStatus::ok);
  EXPECT_EQ(frame.header.sequence, 2u);
  EXPECT_EQ(camera->counters().reconnects, 1u);
}

TEST_F(OpenCvFakeDevice, ReopenedDeviceOfAnotherSizeDeliversNothing) {
  auto camera = configured();
  ASSERT_EQ(camera->start(), HalStatus::ok);
  script_->width = 20;
  script_->fail_next = true;
  ASSERT_TRUE(read_until(*camera, [&] { return camera->stats().reopened == 1; }));
  emit(2);
  hal::ColorFrame frame;
  EXPECT_EQ(camera->read(frame), HalStatus::no_data);
  EXPECT_EQ(camera->stats().size_mismatches, 2u);
}

TEST_F(OpenCvFakeDevice, ThrowingBackendCountsAsLoss) {
  auto camera = configured();
  ASSERT_EQ(camera->start(), HalStatus::ok);
  script_->failing_opens = 1000000;  // stays away
  script_->throw_next = true;
  ASSERT_TRUE(eventually([&] { return camera->stats().device_lost; }));
  hal::ColorFrame frame;
  EXPECT_EQ(camera->read(frame), HalStatus::disconnected);
  ASSERT_TRUE(read_until(*camera, [&] { return camera->stats().reconnect_attempts >= 2; }));
  EXPECT_EQ(camera->stop(), HalStatus::ok);
  EXPECT_EQ(camera->cleanup(), HalStatus::ok);  // joins the thread in the middle of its attempts
}

// Reopen attempts are timed on the injected clock by read(): real time alone never brings one,
// and each comes at the first read at or after its due time (the interval after the read that
// saw the loss, then after the read that asked for the previous attempt).
TEST_F(OpenCvFakeDevice, ReopenAttemptsFollowTheInjectedClock) {
  config_.reconnect_interval_s = 0.05;
  auto camera = configured();
  ASSERT_EQ(camera->start(), HalStatus::ok);
  emit(1);
  hal::ColorFrame frame;
  ASSERT_EQ(camera->read(frame), HalStatus::ok);
  script_->failing_opens = 1000000;  // away until the test lets it back
  script_->fail_next = true;
  ASSERT_TRUE(eventually([&] { return camera->stats().device_lost; }));
  const auto attempts = [&] { return camera->stats().reconnect_attempts; };
  const auto quiet = [] { std::this_thread::sleep_for(std::chrono::milliseconds(50)); };  // time to act on a request

  EXPECT_EQ(camera->read(frame), HalStatus::disconnected);      // loss seen at 20.00: first attempt due at 20.05
  std::this_thread::sleep_for(std::chrono::milliseconds(200));  // four intervals of real time
  EXPECT_EQ(camera->read(frame), HalStatus::disconnected);
  ASSERT_EQ(clock_.advance(0.04), HalStatus::ok);  // 20.04
  EXPECT_EQ(camera->read(frame), HalStatus::disconnected);
  quiet();
  EXPECT_EQ(attempts(), 0u) << "no attempt before the clock reaches the interval";
  EXPECT_EQ(script_->opens.load(), 1);

  ASSERT_EQ(clock_.advance(0.02), HalStatus::ok);  // 20.06: due; the next one at 20.11
  EXPECT_EQ(camera->read(frame), HalStatus::disconnected);
  ASSERT_TRUE(eventually([&] { return attempts() == 1; }));
  ASSERT_EQ(clock_.advance(0.04), HalStatus::ok);  // 20.10
  EXPECT_EQ(camera->read(frame), HalStatus::disconnected);
  quiet();
  EXPECT_EQ(attempts(), 1u);

  // 20.12: due (reads at the same clock time until the thread has finished the last attempt).
  ASSERT_EQ(clock_.advance(0.02), HalStatus::ok);
  ASSERT_TRUE(eventually([&] {
    (void)camera->read(frame);
    return attempts() == 2;
  }));
  quiet();
  EXPECT_EQ(attempts(), 2u) << "one attempt per due time, however many reads";

  script_->failing_opens = 0;  // back: the next attempt, due at 20.17, succeeds
  ASSERT_EQ(clock_.advance(0.04), HalStatus::ok);
  EXPECT_EQ(camera->read(frame), HalStatus::disconnected);
  quiet();
  EXPECT_EQ(camera->stats().reopened, 0u);
  ASSERT_EQ(clock_.advance(0.02), HalStatus::ok);
  ASSERT_TRUE(eventually([&] {
    (void)camera->read(frame);
    return camera->stats().reopened == 1;
  }));
  EXPECT_EQ(attempts(), 3u);
  EXPECT_FALSE(camera->stats().device_lost);
  emit(1);
  ASSERT_EQ(camera->read(frame), HalStatus::ok);
  EXPECT_EQ(camera->counters().reconnects, 1u);
}

TEST_F(OpenCvFakeDevice, AbsentAtConfigure) {
  script_->failing_opens = 1;
  OpenCvCamera camera(clock_, config_, std::make_shared<FakeFactory>(script_, true));
  EXPECT_EQ(camera.configure(), HalStatus::disconnected);
  EXPECT_EQ(camera.last_error(), "fake device absent");
}

// configure waits for the first frame of a source that has none yet (idle) up to 5 s on the
// injected clock. The fake's idle calls run in the test's thread here and advance the clock.
TEST(OpenCvFirstFrame, WaitTimesOutWhenTheInjectedClockPassesFiveSeconds) {
  ManualClock clock(10.0);
  auto script = std::make_shared<FakeScript>();  // no permits: every call is idle
  script->on_idle = [&clock] { (void)clock.advance(1.0); };
  OpenCvCameraConfig config;
  config.location = "fake";
  config.playback = OpenCvPlayback::stepped;  // no decoder thread: next() runs in this thread only
  OpenCvCamera camera(clock, config, std::make_shared<FakeFactory>(script, false));
  const auto began = std::chrono::steady_clock::now();
  EXPECT_EQ(camera.configure(), HalStatus::timeout);
  const double real_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - began).count();
  EXPECT_LT(real_s, 2.5) << "decided by the injected clock, not by the 5 s real-time cap";
  EXPECT_EQ(script->calls.load(), 6) << "the first check after the clock passed 15 s";
  EXPECT_DOUBLE_EQ(clock.now_s(), 16.0);
  EXPECT_NE(camera.last_error().find("no first frame within 5 s"), std::string::npos) << camera.last_error();
}

TEST(OpenCvFirstFrame, FrameBeforeTheInjectedDeadlineIsTaken) {
  ManualClock clock(10.0);
  auto script = std::make_shared<FakeScript>();
  FakeScript& fake = *script;
  int idle_calls = 0;
  fake.on_idle = [&clock, &fake, &idle_calls] {
    (void)clock.advance(1.2);
    if (++idle_calls == 4) fake.permits = 1;  // the frame comes when the clock shows 14.8
  };
  OpenCvCameraConfig config;
  config.location = "fake";
  config.playback = OpenCvPlayback::stepped;
  OpenCvCamera camera(clock, config, std::make_shared<FakeFactory>(script, false));
  ASSERT_EQ(camera.configure(), HalStatus::ok) << camera.last_error();
  EXPECT_EQ(idle_calls, 4);
  EXPECT_NEAR(clock.now_s(), 14.8, 1e-9);
  EXPECT_EQ(camera.width(), 16);
  fake.on_idle = nullptr;
  EXPECT_EQ(camera.cleanup(), HalStatus::ok);
}

// wait_buffered cannot see a ManualClock move (its only thread is the one waiting): real time caps
// the wait, so a decoder with nothing to give never hangs the caller.
TEST(OpenCvWaitBuffered, ManualClockWaitIsCappedByRealTime) {
  ManualClock clock(10.0);
  auto script = std::make_shared<FakeScript>();
  script->permits = 1;  // the first frame only, then idle for good
  OpenCvCameraConfig config;
  config.location = "fake";
  OpenCvCamera camera(clock, config, std::make_shared<FakeFactory>(script, false));
  ASSERT_EQ(camera.configure(), HalStatus::ok) << camera.last_error();
  ASSERT_EQ(camera.start(), HalStatus::ok);
  EXPECT_TRUE(camera.wait_buffered(1, 5.0)) << "the first frame is buffered";
  const auto began = std::chrono::steady_clock::now();
  EXPECT_FALSE(camera.wait_buffered(2, 0.2));
  const double real_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - began).count();
  EXPECT_GE(real_s, 0.2);
  EXPECT_LT(real_s, 5.0);
  EXPECT_DOUBLE_EQ(clock.now_s(), 10.0);
  EXPECT_FALSE(camera.wait_buffered(2, 0.0)) << "no budget: answers at once";
}

TEST(OpenCvV4l2, AbsentDeviceIsAClearError) {
  ManualClock clock;
  OpenCvCameraConfig config;
  config.source = OpenCvSource::v4l2_device;
  config.location = "/dev/video-pliant-absent";
  OpenCvCamera by_path(clock, config);
  EXPECT_EQ(by_path.configure(), HalStatus::disconnected);
  EXPECT_NE(by_path.last_error().find("no such device"), std::string::npos) << by_path.last_error();

  std::error_code ec;
  if (std::filesystem::exists("/dev/video63", ec)) GTEST_SKIP() << "/dev/video63 exists here";
  config.location = "63";
  OpenCvCamera by_index(clock, config);
  EXPECT_EQ(by_index.configure(), HalStatus::disconnected);
  EXPECT_NE(by_index.last_error().find("cannot open"), std::string::npos) << by_index.last_error();
}

TEST(OpenCvV4l2, LiveWebcamWhenPresent) {
  std::string device;
  std::error_code ec;
  for (int n = 0; n < 64 && device.empty(); ++n) {
    const std::string path = "/dev/video" + std::to_string(n);
    if (std::filesystem::exists(path, ec)) device = path;
  }
  if (device.empty()) GTEST_SKIP() << "no /dev/video* device: the live V4L2 test needs a webcam";
  hal::SteadyClock clock;
  OpenCvCameraConfig config;
  config.source = OpenCvSource::v4l2_device;
  config.location = device;
  OpenCvCamera camera(clock, config);
  const HalStatus configured = camera.configure();
  if (configured != HalStatus::ok) GTEST_SKIP() << device << " is not a usable capture device: " << camera.last_error();
  ASSERT_EQ(camera.start(), HalStatus::ok);
  hal::ColorFrame frame;
  bool got = false;
  for (int attempt = 0; attempt < 50 && !got; ++attempt) {
    (void)camera.wait_buffered(1, 0.2);
    got = camera.read(frame) == HalStatus::ok;
  }
  ASSERT_TRUE(got) << "no frame from " << device << " within about 10 s";
  EXPECT_EQ(frame.width, camera.width());
  EXPECT_GT(frame.width, 0);
  EXPECT_LE(frame.header.stamp_s, clock.now_s());
}

}  // namespace
}  // namespace pliant::drivers
