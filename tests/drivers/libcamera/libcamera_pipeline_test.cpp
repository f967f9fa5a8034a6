// The libcamera camera on a fake backend: request/complete/requeue, the triple buffer (newest
// wins, a held frame is never written), sequence numbers and drops, failed and short buffers,
// cancellation at stop, restart, disconnection, stamps, configure errors, and a threaded stress
// run that checks frames are never torn.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <cstring>
#include <memory>
#include <thread>
#include <vector>

#include "fake_backend.hpp"
#include "frame_pipeline.hpp"
#include "pliant/drivers/libcamera/libcamera_camera.hpp"

namespace pliant::drivers {
namespace {

using hal::HalStatus;
using libcamera_detail::CompletionStatus;
using libcamera_detail::RawFormat;
using libcamera_test::complete;
using libcamera_test::FakeBackend;
using libcamera_test::FakeBackendState;

constexpr int kWidth = 8;
constexpr int kHeight = 4;
constexpr std::size_t kStride = 20;  // 16 bytes of YUYV per row plus padding
constexpr std::size_t kFrameBytes = kStride * kHeight;

// Fills buffer `index` with a flat grey of full-range luma `y` (U = V = 128).
void fill_yuyv(FakeBackendState& state, int index, std::uint8_t y) {
  std::vector<std::uint8_t>& bytes = state.buffers[static_cast<std::size_t>(index)];
  for (std::size_t row = 0; row < kHeight; ++row) {
    for (std::size_t i = 0; i < 16; i += 2) {
      bytes[row * kStride + i] = y;
      bytes[row * kStride + i + 1] = 128;
    }
  }
}

class LibcameraFake : public ::testing::Test {
 protected:
  LibcameraFake() {
    state_.setup.format = RawFormat::yuyv;
    state_.setup.width = kWidth;
    state_.setup.height = kHeight;
    state_.setup.stride = kStride;
    state_.setup.full_range = true;
    state_.setup.description = "fake 8x4-YUYV";
    libcamera_test::make_buffers(state_, 3, kFrameBytes);
  }
  std::unique_ptr<LibcameraCamera> camera(hal::PixelFormat format = hal::PixelFormat::rgb8) {
    LibcameraCameraConfig config;
    config.format = format;
    return std::make_unique<LibcameraCamera>(clock_, config, std::make_unique<FakeBackend>(state_));
  }
  // Completes buffer `index` as a flat frame of luma `y`.
  void deliver(int index, std::uint32_t sequence, std::uint8_t y) {
    fill_yuyv(state_, index, y);
    complete(state_, index, CompletionStatus::success, sequence);
  }

  FakeBackendState state_;
  hal::ManualClock clock_{3.0};
};

TEST_F(LibcameraFake, RequestsAreRequeuedAsSoonAsTheyComplete) {
  auto cam = camera();
  ASSERT_EQ(cam->configure(), HalStatus::ok) << cam->last_error();
  EXPECT_EQ(cam->stream_description(), "fake 8x4-YUYV");
  EXPECT_EQ(cam->width(), kWidth);
  EXPECT_EQ(cam->height(), kHeight);
  hal::ColorFrame frame;
  EXPECT_EQ(cam->read(frame), HalStatus::wrong_state);
  ASSERT_EQ(cam->start(), HalStatus::ok);
  EXPECT_EQ(state_.queued, (std::vector<int>{0, 1, 2}));
  EXPECT_EQ(cam->read(frame), HalStatus::no_data);

  deliver(1, 0, 90);
  EXPECT_EQ(state_.queued, (std::vector<int>{0, 2, 1}));  // back with the camera at once
  ASSERT_EQ(cam->read(frame), HalStatus::ok);
  EXPECT_EQ(frame.header.sequence, 1u);
  EXPECT_EQ(frame.width, kWidth);
  EXPECT_EQ(frame.height, kHeight);
  EXPECT_EQ(frame.stride_bytes, kWidth * 3);
  EXPECT_EQ(frame.format, hal::PixelFormat::rgb8);
  for (int i = 0; i < kWidth * kHeight * 3; ++i) ASSERT_EQ(frame.data[i], 90) << i;
  EXPECT_EQ(cam->read(frame), HalStatus::no_data);
  const LibcameraCameraStats stats = cam->stats();
  EXPECT_EQ(stats.completed, 1u);
  EXPECT_EQ(stats.converted, 1u);
  EXPECT_EQ(state_.requeues.load(), 1);
}

TEST_F(LibcameraFake, NewestFrameWinsAndTheHeldFrameIsNeverWritten) {
  auto cam = camera(hal::PixelFormat::mono8);
  ASSERT_EQ(cam->configure(), HalStatus::ok);
  ASSERT_EQ(cam->start(), HalStatus::ok);
  deliver(0, 0, 10);
  hal::ColorFrame held;
  ASSERT_EQ(cam->read(held), HalStatus::ok);
  const std::uint8_t* held_data = held.data;
  // Three more frames while the loop holds the first one: it stays intact.
  deliver(1, 1, 20);
  deliver(2, 2, 30);
  deliver(0, 3, 40);
  for (int i = 0; i < kWidth * kHeight; ++i) ASSERT_EQ(held_data[i], 10) << i;
  hal::ColorFrame frame;
  ASSERT_EQ(cam->read(frame), HalStatus::ok);
  EXPECT_EQ(frame.header.sequence, 4u);
  EXPECT_EQ(frame.data[0], 40);
  EXPECT_EQ(cam->stats().overwritten, 2u);
  EXPECT_EQ(cam->counters().dropped, 2u);
}

TEST_F(LibcameraFake, CameraSequenceGapsFailedAndShortBuffersAreDrops) {
  auto cam = camera();
  ASSERT_EQ(cam->configure(), HalStatus::ok);
  ASSERT_EQ(cam->start(), HalStatus::ok);
  hal::ColorFrame frame;
  deliver(0, 100, 50);  // the camera's numbering starts anywhere: this is 1
  ASSERT_EQ(cam->read(frame), HalStatus::ok);
  EXPECT_EQ(frame.header.sequence, 1u);
  deliver(1, 103, 60);  // the camera lost 101 and 102
  ASSERT_EQ(cam->read(frame), HalStatus::ok);
  EXPECT_EQ(frame.header.sequence, 4u);
  EXPECT_EQ(cam->counters().dropped, 2u);

  complete(state_, 2, CompletionStatus::error, 104);  // a failed buffer
  fill_yuyv(state_, 0, 70);
  complete(state_, 0, CompletionStatus::success, 105, 0, kStride * (kHeight - 1) + 15);  // one byte short
  EXPECT_EQ(cam->read(frame), HalStatus::no_data);
  deliver(1, 106, 80);
  ASSERT_EQ(cam->read(frame), HalStatus::ok);
  EXPECT_EQ(frame.header.sequence, 7u);
  EXPECT_EQ(frame.data[0], 80);
  const LibcameraCameraStats stats = cam->stats();
  EXPECT_EQ(stats.failed_buffers, 1u);
  EXPECT_EQ(stats.conversion_errors, 1u);
  EXPECT_EQ(cam->counters().dropped, 4u);
  EXPECT_EQ(state_.requeues.load(), 5);  // failed and short buffers go back too
  EXPECT_EQ(state_.queued.size(), 3u);
}

TEST_F(LibcameraFake, StopCancelsQueuedRequestsAndRestartContinuesNumbering) {
  auto cam = camera();
  ASSERT_EQ(cam->configure(), HalStatus::ok);
  ASSERT_EQ(cam->start(), HalStatus::ok);
  deliver(0, 7, 50);
  deliver(1, 8, 51);  // converted, never read before the stop
  hal::ColorFrame frame;
  ASSERT_EQ(cam->stop(), HalStatus::ok);
  EXPECT_EQ(cam->stats().cancelled, 3u);
  EXPECT_TRUE(state_.queued.empty());
  EXPECT_EQ(state_.requeues.load(), 2);  // none for the cancelled ones

  ASSERT_EQ(cam->start(), HalStatus::ok);
  EXPECT_EQ(cam->read(frame), HalStatus::no_data);  // the frame from before the stop is not delivered
  deliver(2, 0, 52);                                // the camera restarts its numbering
  ASSERT_EQ(cam->read(frame), HalStatus::ok);
  EXPECT_EQ(frame.header.sequence, 3u);
  EXPECT_EQ(frame.data[0], 52);
  ASSERT_EQ(cam->stop(), HalStatus::ok);
  ASSERT_EQ(cam->cleanup(), HalStatus::ok);
  EXPECT_EQ(state_.closes, 1);
  EXPECT_EQ(cam->width(), 0);
}

TEST_F(LibcameraFake, RefusedRequeueIsCounted) {
  auto cam = camera();
  ASSERT_EQ(cam->configure(), HalStatus::ok);
  ASSERT_EQ(cam->start(), HalStatus::ok);
  state_.refuse_requeue = true;
  deliver(0, 0, 1);
  EXPECT_EQ(cam->stats().requeue_errors, 1u);
}

TEST_F(LibcameraFake, DisconnectionIsReportedUntilCleanup) {
  auto cam = camera();
  ASSERT_EQ(cam->configure(), HalStatus::ok);
  ASSERT_EQ(cam->start(), HalStatus::ok);
  deliver(0, 0, 1);
  state_.sink->on_disconnected();
  hal::ColorFrame frame;
  EXPECT_EQ(cam->read(frame), HalStatus::disconnected);
  EXPECT_EQ(cam->read(frame), HalStatus::disconnected);
  EXPECT_TRUE(cam->stats().lost);
  EXPECT_EQ(cam->counters().disconnects, 1u);
  ASSERT_EQ(cam->stop(), HalStatus::ok);
  ASSERT_EQ(cam->cleanup(), HalStatus::ok);
  ASSERT_EQ(cam->configure(), HalStatus::ok);  // a fresh configure reopens
  ASSERT_EQ(cam->start(), HalStatus::ok);
  deliver(0, 0, 1);
  EXPECT_EQ(cam->read(frame), HalStatus::ok);
}

// The monotonic clock the pipeline reads, set by the test.
std::atomic<std::uint64_t> g_fake_now_ns{0};
std::uint64_t fake_now_ns() noexcept { return g_fake_now_ns.load(); }

TEST_F(LibcameraFake, StampIsTheClockMinusTheFramesAge) {
  libcamera_detail::StreamSetup setup = state_.setup;
  FakeBackend backend(state_);
  libcamera_detail::FramePipeline pipeline(setup, hal::PixelFormat::rgb8, backend, &fake_now_ns);
  std::string error;
  pipeline.begin();
  ASSERT_EQ(backend.start(pipeline, error), HalStatus::ok);
  hal::ColorFrame frame;

  // A sensor timestamp 20 ms before completion, read 5 ms after: 25 ms old.
  g_fake_now_ns = 10'000'000'000ull;
  complete(state_, 0, CompletionStatus::success, 0, 9'980'000'000ull);
  g_fake_now_ns = 10'005'000'000ull;
  ASSERT_EQ(pipeline.take(frame, clock_), HalStatus::ok);
  EXPECT_NEAR(frame.header.stamp_s, 3.0 - 0.025, 1e-9);

  // Implausible sensor timestamps (none, from the future, 10 s old): the completion time.
  for (const std::uint64_t stamp : {std::uint64_t{0}, std::uint64_t{10'006'000'000}, std::uint64_t{5'000'000'000}}) {
    g_fake_now_ns = 20'000'000'000ull;
    complete(state_, 1, CompletionStatus::success, 1, stamp);
    g_fake_now_ns = 20'002'000'000ull;
    ASSERT_EQ(pipeline.take(frame, clock_), HalStatus::ok);
    EXPECT_NEAR(frame.header.stamp_s, 3.0 - 0.002, 1e-9) << stamp;
  }
  pipeline.end();
  backend.stop();
}

TEST_F(LibcameraFake, SemiPlanarBuffersInOneOrTwoPlanes) {
  for (const int planes : {1, 2}) {
    FakeBackendState state;
    state.setup.format = RawFormat::nv12;
    state.setup.width = 4;
    state.setup.height = 2;
    state.setup.stride = 4;
    state.setup.full_range = true;
    state.planes_per_buffer = planes;
    state.plane0_bytes = 8;
    libcamera_test::make_buffers(state, 2, 12);
    for (auto& bytes : state.buffers) {
      std::fill(bytes.begin(), bytes.begin() + 8, std::uint8_t{100});  // Y
      std::fill(bytes.begin() + 8, bytes.end(), std::uint8_t{128});    // U, V: grey
    }
    LibcameraCamera cam(clock_, LibcameraCameraConfig{}, std::make_unique<FakeBackend>(state));
    ASSERT_EQ(cam.configure(), HalStatus::ok);
    ASSERT_EQ(cam.start(), HalStatus::ok);
    complete(state, 0, CompletionStatus::success, 0);
    hal::ColorFrame frame;
    ASSERT_EQ(cam.read(frame), HalStatus::ok) << planes;
    for (int i = 0; i < 4 * 2 * 3; ++i) ASSERT_EQ(frame.data[i], 100) << planes << " " << i;
    // Bytes used that cut the chroma rows (one plane) or the luma rows (two planes).
    complete(state, 1, CompletionStatus::success, 1, 0, planes == 1 ? 10 : 7);
    EXPECT_EQ(cam.stats().conversion_errors, 1u) << planes;
  }
}

TEST_F(LibcameraFake, ConfigureErrors) {
  {
    state_.open_status = HalStatus::disconnected;
    state_.open_error = "no camera: libcamera lists none";
    auto cam = camera();
    EXPECT_EQ(cam->configure(), HalStatus::disconnected);
    EXPECT_EQ(cam->last_error(), "no camera: libcamera lists none");
    state_.open_status = HalStatus::ok;
  }
  {
    state_.setup.stride = 15;  // below one YUYV row of 8 pixels
    auto cam = camera();
    EXPECT_EQ(cam->configure(), HalStatus::io_error);
    EXPECT_NE(cam->last_error().find("unusable stream"), std::string::npos);
    state_.setup.stride = kStride;
  }
  {
    state_.start_status = HalStatus::io_error;
    auto cam = camera();
    ASSERT_EQ(cam->configure(), HalStatus::ok);
    EXPECT_EQ(cam->start(), HalStatus::io_error);
    EXPECT_EQ(cam->state(), hal::LifecycleState::inactive);
    state_.start_status = HalStatus::ok;
  }
  const auto refused = [&](LibcameraCameraConfig config, const char* words) {
    LibcameraCamera cam(clock_, config, std::make_unique<FakeBackend>(state_));
    EXPECT_EQ(cam.configure(), HalStatus::invalid_argument) << words;
    EXPECT_NE(cam.last_error().find(words), std::string::npos) << cam.last_error();
  };
  LibcameraCameraConfig c;
  c.buffer_count = 1;
  refused(c, "buffer_count");
  c = {};
  c.width = 640;
  refused(c, "both width and height");
  c = {};
  c.height = 20000;
  c.width = 10;
  refused(c, "width/height");
  c = {};
  c.format = static_cast<hal::PixelFormat>(5);
  refused(c, "pixel format");
}

// Frames completed from another thread while the loop reads: every delivered frame is whole
// (one grey level everywhere), sequence numbers only increase, and the counts add up.
TEST_F(LibcameraFake, ConcurrentCompletionsNeverTearAFrame) {
  auto cam = camera(hal::PixelFormat::mono8);
  ASSERT_EQ(cam->configure(), HalStatus::ok);
  ASSERT_EQ(cam->start(), HalStatus::ok);
  constexpr int kFrames = 3000;
  std::atomic<bool> done{false};
  std::thread producer([&] {
    for (int k = 0; k < kFrames; ++k) {
      const int index = state_.queued.front();  // only this thread touches the queue now
      deliver(index, static_cast<std::uint32_t>(k), static_cast<std::uint8_t>(k % 251));
    }
    done = true;
  });
  std::uint64_t last = 0;
  int delivered = 0;
  hal::ColorFrame frame;
  while (!done.load() || cam->stats().converted > static_cast<std::uint64_t>(delivered) + cam->stats().overwritten) {
    const HalStatus status = cam->read(frame);
    if (status == HalStatus::no_data) continue;
    ASSERT_EQ(status, HalStatus::ok);
    ASSERT_GT(frame.header.sequence, last);
    last = frame.header.sequence;
    ++delivered;
    const std::uint8_t first = frame.data[0];
    ASSERT_EQ(first, static_cast<std::uint8_t>((frame.header.sequence - 1) % 251));
    for (int i = 1; i < kWidth * kHeight; ++i)
      ASSERT_EQ(frame.data[i], first) << "torn frame " << frame.header.sequence;
  }
  producer.join();
  const LibcameraCameraStats stats = cam->stats();
  EXPECT_EQ(stats.converted, static_cast<std::uint64_t>(kFrames));
  EXPECT_EQ(stats.converted, static_cast<std::uint64_t>(delivered) + stats.overwritten);
  EXPECT_EQ(cam->counters().dropped + static_cast<std::uint64_t>(delivered), last);
}

}  // namespace
}  // namespace pliant::drivers
