// OpenCV camera on files: an MJPEG video and PNG sequences written by the test, played stepped and
// in real time on a ManualClock; end of stream, broken inputs and configuration errors.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <string>

#include <opencv2/core.hpp>

#include "opencv_test_media.hpp"
#include "pliant/drivers/opencv/opencv_camera.hpp"
#include "support/temp_dir.hpp"

namespace pliant::drivers {
namespace {

using hal::HalStatus;
using hal::ManualClock;
using opencv_test::frame_bgr;
using opencv_test::frame_index_of;

constexpr int kVideoFrames = 6;
constexpr double kVideoFps = 10;

// Pixel (x, y) of a frame as (B, G, R) whatever the delivered format (mono8: the gray value
// three times).
cv::Vec3b pixel_bgr(const hal::ColorFrame& frame, int x, int y) {
  const std::uint8_t* p = frame.data + y * frame.stride_bytes + x * hal::pixel_bytes(frame.format);
  switch (frame.format) {
    case hal::PixelFormat::bgr8: return cv::Vec3b(p[0], p[1], p[2]);
    case hal::PixelFormat::rgb8: return cv::Vec3b(p[2], p[1], p[0]);
    case hal::PixelFormat::mono8: return cv::Vec3b(p[0], p[0], p[0]);
  }
  return {};
}

// The frame index a delivered video frame shows (MJPEG is lossy: a tolerance of 8 per channel;
// neighbouring frames differ by 17 or more in every channel).
int video_frame_index(const hal::ColorFrame& frame) {
  return frame_index_of(pixel_bgr(frame, frame.width / 2, frame.height / 2), kVideoFrames, 8);
}

class OpenCvVideo : public ::testing::Test {
 protected:
  void SetUp() override {
    video_ = dir_ / "clip.avi";
    opencv_test::write_video(video_, kVideoFrames, kVideoFps);
  }
  OpenCvCameraConfig video_config(OpenCvPlayback playback) const {
    OpenCvCameraConfig config;
    config.source = OpenCvSource::video_file;
    config.location = video_;
    config.playback = playback;
    return config;
  }

  test_support::TempDir dir_{"pliant_opencv_"};
  std::string video_;
};

TEST_F(OpenCvVideo, SteppedDeliversEveryFrameThenEndOfStream) {
  ManualClock clock(50.0);
  OpenCvCamera camera(clock, video_config(OpenCvPlayback::stepped));
  ASSERT_EQ(camera.configure(), HalStatus::ok) << camera.last_error();
  EXPECT_EQ(camera.width(), 64);
  EXPECT_EQ(camera.height(), 48);
  ASSERT_EQ(camera.start(), HalStatus::ok);
  hal::ColorFrame frame;
  for (int k = 0; k < kVideoFrames; ++k) {
    ASSERT_EQ(camera.read(frame), HalStatus::ok) << "frame " << k;
    EXPECT_EQ(frame.header.sequence, static_cast<std::uint64_t>(k + 1));
    EXPECT_EQ(frame.width, 64);
    EXPECT_EQ(frame.height, 48);
    EXPECT_EQ(frame.stride_bytes, 64 * 3);
    EXPECT_EQ(frame.format, hal::PixelFormat::rgb8);
    EXPECT_EQ(video_frame_index(frame), k);
    // Media time from the file (10 fps), stamps keep the file's intervals from the start time.
    EXPECT_NEAR(camera.media_time_s(), k / kVideoFps, 1e-9);
    EXPECT_NEAR(frame.header.stamp_s, 50.0 + k / kVideoFps, 1e-9);
    EXPECT_FALSE(camera.end_of_stream());
  }
  EXPECT_EQ(camera.read(frame), HalStatus::no_data);
  EXPECT_TRUE(camera.end_of_stream());
  EXPECT_EQ(camera.read(frame), HalStatus::no_data);
  const OpenCvCameraStats stats = camera.stats();
  EXPECT_EQ(stats.decoded, static_cast<std::uint64_t>(kVideoFrames));
  EXPECT_TRUE(stats.end_of_stream);
  EXPECT_FALSE(stats.ended_early);
  EXPECT_EQ(stats.decode_errors + stats.size_mismatches + stats.skipped, 0u);
  EXPECT_EQ(camera.counters().samples, static_cast<std::uint64_t>(kVideoFrames));
  EXPECT_EQ(camera.counters().dropped, 0u);
  EXPECT_EQ(camera.counters().no_data, 2u);
  EXPECT_EQ(camera.stop(), HalStatus::ok);
  EXPECT_EQ(camera.cleanup(), HalStatus::ok);
}

TEST_F(OpenCvVideo, RealTimeDeliversFramesWhenTheClockReachesThem) {
  ManualClock clock(100.0);
  OpenCvCameraConfig config = video_config(OpenCvPlayback::real_time);
  config.format = hal::PixelFormat::bgr8;
  config.ring_frames = 3;  // smaller than the clip: the decoder refills as frames are read
  OpenCvCamera camera(clock, config);
  ASSERT_EQ(camera.configure(), HalStatus::ok) << camera.last_error();
  ASSERT_EQ(camera.start(), HalStatus::ok);
  hal::ColorFrame frame;

  // Frame 0 is due at the start.
  ASSERT_TRUE(camera.wait_buffered(1, 10.0));
  ASSERT_EQ(camera.read(frame), HalStatus::ok);
  EXPECT_EQ(frame.header.sequence, 1u);
  EXPECT_EQ(video_frame_index(frame), 0);
  EXPECT_DOUBLE_EQ(frame.header.stamp_s, 100.0);
  EXPECT_EQ(frame.format, hal::PixelFormat::bgr8);
  EXPECT_EQ(camera.read(frame), HalStatus::no_data);  // nothing new at the same time

  // Frame 1 is due 0.1 s later; not before.
  ASSERT_TRUE(camera.wait_buffered(1, 10.0));
  ASSERT_EQ(clock.set(100.099), HalStatus::ok);
  EXPECT_EQ(camera.read(frame), HalStatus::no_data);
  ASSERT_EQ(clock.set(100.1), HalStatus::ok);
  ASSERT_EQ(camera.read(frame), HalStatus::ok);
  EXPECT_EQ(frame.header.sequence, 2u);
  EXPECT_EQ(video_frame_index(frame), 1);
  EXPECT_DOUBLE_EQ(frame.header.stamp_s, 100.1);

  // Reading late: frames 2 and 3 are both due; the newest is delivered, frame 2 is skipped.
  ASSERT_TRUE(camera.wait_buffered(2, 10.0));
  ASSERT_EQ(clock.set(100.35), HalStatus::ok);
  ASSERT_EQ(camera.read(frame), HalStatus::ok);
  EXPECT_EQ(frame.header.sequence, 4u);
  EXPECT_EQ(video_frame_index(frame), 3);
  EXPECT_NEAR(camera.media_time_s(), 0.3, 1e-9);
  EXPECT_EQ(camera.stats().skipped, 1u);
  EXPECT_EQ(camera.counters().dropped, 1u);

  // Ten seconds stopped pause the playback: frame 4 is due 0.4 s after the start plus 10 s.
  ASSERT_EQ(camera.stop(), HalStatus::ok);
  ASSERT_EQ(clock.advance(10.0), HalStatus::ok);
  ASSERT_EQ(camera.start(), HalStatus::ok);
  ASSERT_TRUE(camera.wait_buffered(2, 10.0));
  EXPECT_EQ(camera.read(frame), HalStatus::no_data);
  ASSERT_EQ(clock.set(110.4), HalStatus::ok);
  ASSERT_EQ(camera.read(frame), HalStatus::ok);
  EXPECT_EQ(video_frame_index(frame), 4);
  EXPECT_NEAR(frame.header.stamp_s, 110.4, 1e-9);
  ASSERT_EQ(clock.set(110.5), HalStatus::ok);
  ASSERT_EQ(camera.read(frame), HalStatus::ok);
  EXPECT_EQ(video_frame_index(frame), 5);
  EXPECT_EQ(frame.header.sequence, 6u);

  // The end: no more frames, ever.
  ASSERT_TRUE(camera.wait_buffered(1, 10.0));
  ASSERT_EQ(clock.advance(5.0), HalStatus::ok);
  EXPECT_EQ(camera.read(frame), HalStatus::no_data);
  EXPECT_TRUE(camera.end_of_stream());
  EXPECT_EQ(camera.counters().samples, 5u);
  EXPECT_EQ(camera.stats().decoded, 6u);
}

TEST_F(OpenCvVideo, CleanupAndConfigureAgainRestartsTheFile) {
  ManualClock clock;
  OpenCvCamera camera(clock, video_config(OpenCvPlayback::stepped));
  hal::ColorFrame frame;
  for (int round = 0; round < 2; ++round) {
    ASSERT_EQ(camera.configure(), HalStatus::ok) << camera.last_error();
    ASSERT_EQ(camera.start(), HalStatus::ok);
    ASSERT_EQ(camera.read(frame), HalStatus::ok);
    ASSERT_EQ(camera.read(frame), HalStatus::ok);
    EXPECT_EQ(frame.header.sequence, 2u);
    EXPECT_EQ(video_frame_index(frame), 1);
    ASSERT_EQ(camera.stop(), HalStatus::ok);
    ASSERT_EQ(camera.cleanup(), HalStatus::ok);
  }
  // Lifecycle errors come from the HAL wrapper.
  EXPECT_EQ(camera.read(frame), HalStatus::wrong_state);
  EXPECT_EQ(camera.width(), 0);
}

TEST_F(OpenCvVideo, DestroyedWhileActive) {
  ManualClock clock;
  auto camera = std::make_unique<OpenCvCamera>(clock, video_config(OpenCvPlayback::real_time));
  ASSERT_EQ(camera->configure(), HalStatus::ok) << camera->last_error();
  ASSERT_EQ(camera->start(), HalStatus::ok);
  camera.reset();  // joins the decoder thread
  SUCCEED();
}

TEST_F(OpenCvVideo, TruncatedFileEndsEarly) {
  const std::string cut = dir_ / "cut.avi";
  opencv_test::write_video(cut, 10, kVideoFps);
  std::filesystem::resize_file(cut, std::filesystem::file_size(cut) * 8 / 10);
  ManualClock clock;
  OpenCvCameraConfig config = video_config(OpenCvPlayback::stepped);
  config.location = cut;
  OpenCvCamera camera(clock, config);
  const HalStatus status = camera.configure();
  if (status != HalStatus::ok) {
    // A backend that refuses the damaged file outright: a clear error is the other good outcome.
    EXPECT_EQ(status, HalStatus::io_error);
    EXPECT_FALSE(camera.last_error().empty());
    return;
  }
  ASSERT_EQ(camera.start(), HalStatus::ok);
  hal::ColorFrame frame;
  int delivered = 0;
  while (camera.read(frame) == HalStatus::ok) ++delivered;
  EXPECT_LT(delivered, 10);
  EXPECT_TRUE(camera.end_of_stream());
  EXPECT_TRUE(camera.stats().ended_early);
}

TEST(OpenCvFileErrors, MissingCorruptAndDirectoryVideos) {
  test_support::TempDir dir("pliant_opencv_");
  ManualClock clock;
  OpenCvCameraConfig config;
  config.source = OpenCvSource::video_file;

  config.location = dir / "absent.avi";
  OpenCvCamera absent(clock, config);
  EXPECT_EQ(absent.configure(), HalStatus::io_error);
  EXPECT_NE(absent.last_error().find("no such file"), std::string::npos) << absent.last_error();
  EXPECT_EQ(absent.state(), hal::LifecycleState::unconfigured);

  config.location = dir / "garbage.avi";
  opencv_test::write_bytes(config.location, std::string("RIFF\x10\x00\x00\x00"
                                                        "AVI LIST garbage, not a video",
                                                        37));
  OpenCvCamera corrupt(clock, config);
  EXPECT_EQ(corrupt.configure(), HalStatus::io_error);
  EXPECT_NE(corrupt.last_error().find("cannot decode"), std::string::npos) << corrupt.last_error();

  config.location = dir / "empty.avi";
  opencv_test::write_bytes(config.location, "");
  OpenCvCamera empty(clock, config);
  EXPECT_EQ(empty.configure(), HalStatus::io_error);
  EXPECT_FALSE(empty.last_error().empty());

  config.location = dir.path().string();
  OpenCvCamera directory(clock, config);
  EXPECT_EQ(directory.configure(), HalStatus::io_error);
  EXPECT_NE(directory.last_error().find("not a regular file"), std::string::npos) << directory.last_error();
}

TEST(OpenCvFileErrors, UnreadableFile) {
  if (::geteuid() == 0) GTEST_SKIP() << "running as root: file permissions do not stop reads";
  test_support::TempDir dir("pliant_opencv_");
  const std::string path = dir / "locked.avi";
  opencv_test::write_video(path, 2, kVideoFps);
  std::filesystem::permissions(path, std::filesystem::perms::none);
  ManualClock clock;
  OpenCvCameraConfig config;
  config.source = OpenCvSource::video_file;
  config.location = path;
  OpenCvCamera camera(clock, config);
  EXPECT_EQ(camera.configure(), HalStatus::io_error);
  EXPECT_NE(camera.last_error().find("not readable"), std::string::npos) << camera.last_error();
}

TEST(OpenCvFileErrors, InvalidConfigurations) {
  ManualClock clock;
  const auto refused = [&](OpenCvCameraConfig config, const std::string& words) {
    OpenCvCamera camera(clock, std::move(config));
    EXPECT_EQ(camera.configure(), HalStatus::invalid_argument) << words;
    EXPECT_NE(camera.last_error().find(words), std::string::npos) << camera.last_error();
  };
  OpenCvCameraConfig base;
  base.location = "/nonexistent.avi";
  refused(OpenCvCameraConfig{}, "location is empty");
  OpenCvCameraConfig c = base;
  c.ring_frames = 1;
  refused(c, "ring_frames");
  c = base;
  c.ring_frames = 65;
  refused(c, "ring_frames");
  c = base;
  c.fps = std::nan("");
  refused(c, "fps");
  c = base;
  c.width = -1;
  refused(c, "width");
  c = base;
  c.first_index = -2;
  refused(c, "first_index");
  c = base;
  c.reconnect_interval_s = 0;
  refused(c, "reconnect_interval_s");
  c = base;
  c.source = OpenCvSource::v4l2_device;
  c.location = "0";
  c.playback = OpenCvPlayback::stepped;
  refused(c, "stepped");
  c = base;
  c.format = static_cast<hal::PixelFormat>(7);
  refused(c, "pixel format");
}

// ---- image sequences

class OpenCvSequence : public ::testing::Test {
 protected:
  OpenCvCameraConfig sequence_config(const std::string& location, hal::PixelFormat format) const {
    OpenCvCameraConfig config;
    config.source = OpenCvSource::image_sequence;
    config.location = location;
    config.format = format;
    config.playback = OpenCvPlayback::stepped;
    config.fps = 20;
    return config;
  }
  test_support::TempDir dir_{"pliant_opencv_seq_"};
};

TEST_F(OpenCvSequence, PatternInEveryPixelFormatIsExact) {
  for (int k = 0; k < 4; ++k)
    opencv_test::write_png(dir_ / ("frame_" + std::string(k < 10 ? "000" : "00") + std::to_string(k) + ".png"), k);
  for (const hal::PixelFormat format : {hal::PixelFormat::rgb8, hal::PixelFormat::bgr8, hal::PixelFormat::mono8}) {
    ManualClock clock(2.0);
    OpenCvCamera camera(clock, sequence_config(dir_ / "frame_%04d.png", format));
    ASSERT_EQ(camera.configure(), HalStatus::ok) << camera.last_error();
    ASSERT_EQ(camera.start(), HalStatus::ok);
    hal::ColorFrame frame;
    for (int k = 0; k < 4; ++k) {
      ASSERT_EQ(camera.read(frame), HalStatus::ok);
      EXPECT_EQ(frame.width, 32);
      EXPECT_EQ(frame.height, 24);
      EXPECT_EQ(frame.stride_bytes, 32 * hal::pixel_bytes(format));
      EXPECT_EQ(frame.format, format);
      EXPECT_NEAR(frame.header.stamp_s, 2.0 + k / 20.0, 1e-12);
      const cv::Vec3b want = frame_bgr(k);
      const cv::Vec3b got = pixel_bgr(frame, 31, 23);
      if (format == hal::PixelFormat::mono8) {
        // BT.601 luma, as cvtColor computes it.
        const double luma = 0.299 * want[2] + 0.587 * want[1] + 0.114 * want[0];
        EXPECT_NEAR(got[0], luma, 1.0) << "frame " << k;
      } else {
        EXPECT_EQ(got, want) << "frame " << k;
      }
    }
    EXPECT_EQ(camera.read(frame), HalStatus::no_data);
    EXPECT_TRUE(camera.end_of_stream());
  }
}

TEST_F(OpenCvSequence, FirstIndexIsFoundOrGiven) {
  for (int k = 1; k <= 5; ++k) opencv_test::write_png(dir_ / ("img" + std::to_string(k) + ".png"), k);
  ManualClock clock;
  hal::ColorFrame frame;
  {
    OpenCvCamera camera(clock, sequence_config(dir_ / "img%d.png", hal::PixelFormat::bgr8));
    ASSERT_EQ(camera.configure(), HalStatus::ok) << camera.last_error();  // starts at 1: no img0.png
    ASSERT_EQ(camera.start(), HalStatus::ok);
    ASSERT_EQ(camera.read(frame), HalStatus::ok);
    EXPECT_EQ(pixel_bgr(frame, 0, 0), frame_bgr(1));
  }
  {
    OpenCvCameraConfig config = sequence_config(dir_ / "img%d.png", hal::PixelFormat::bgr8);
    config.first_index = 4;
    OpenCvCamera camera(clock, config);
    ASSERT_EQ(camera.configure(), HalStatus::ok) << camera.last_error();
    ASSERT_EQ(camera.start(), HalStatus::ok);
    ASSERT_EQ(camera.read(frame), HalStatus::ok);
    EXPECT_EQ(pixel_bgr(frame, 0, 0), frame_bgr(4));
    ASSERT_EQ(camera.read(frame), HalStatus::ok);
    EXPECT_EQ(pixel_bgr(frame, 0, 0), frame_bgr(5));
    EXPECT_EQ(camera.read(frame), HalStatus::no_data);
  }
  {
    OpenCvCameraConfig config = sequence_config(dir_ / "img%d.png", hal::PixelFormat::bgr8);
    config.first_index = 9;
    OpenCvCamera camera(clock, config);
    EXPECT_EQ(camera.configure(), HalStatus::io_error);
    EXPECT_NE(camera.last_error().find("img9.png"), std::string::npos) << camera.last_error();
  }
}

TEST_F(OpenCvSequence, DirectoryInNaturalOrderSkippingOtherFiles) {
  const int order[] = {1, 2, 10, 11};
  for (const int k : order) opencv_test::write_png(dir_ / ("shot_" + std::to_string(k) + ".png"), k % 7);
  opencv_test::write_bytes(dir_ / "notes.txt", "not an image");
  std::filesystem::create_directory(dir_ / "sub.png");  // a directory named like an image
  ManualClock clock;
  OpenCvCamera camera(clock, sequence_config(dir_.path().string(), hal::PixelFormat::bgr8));
  ASSERT_EQ(camera.configure(), HalStatus::ok) << camera.last_error();
  ASSERT_EQ(camera.start(), HalStatus::ok);
  hal::ColorFrame frame;
  for (const int k : order) {
    ASSERT_EQ(camera.read(frame), HalStatus::ok);
    EXPECT_EQ(pixel_bgr(frame, 3, 3), frame_bgr(k % 7)) << "shot " << k;
  }
  EXPECT_EQ(camera.read(frame), HalStatus::no_data);
  EXPECT_TRUE(camera.end_of_stream());
  EXPECT_EQ(camera.stats().decode_errors, 0u);
}

TEST_F(OpenCvSequence, CorruptAndResizedFramesAreDroppedAndCounted) {
  // 0 ok, 1 corrupt, 2 another size, 3 ok, 4 empty file, 5 ok.
  const std::string pattern = dir_ / "f%02d.png";
  opencv_test::write_png(dir_ / "f00.png", 0);
  opencv_test::write_bytes(dir_ / "f01.png", std::string("\x89PNG\r\n\x1a\n garbage after a PNG signature", 38));
  opencv_test::write_png(dir_ / "f02.png", 2, 40, 30);
  opencv_test::write_png(dir_ / "f03.png", 3);
  opencv_test::write_bytes(dir_ / "f04.png", "");
  opencv_test::write_png(dir_ / "f05.png", 5);
  for (const OpenCvPlayback playback : {OpenCvPlayback::stepped, OpenCvPlayback::real_time}) {
    ManualClock clock(1.0);
    OpenCvCameraConfig config = sequence_config(pattern, hal::PixelFormat::bgr8);
    config.playback = playback;
    config.ring_frames = 8;
    OpenCvCamera camera(clock, config);
    ASSERT_EQ(camera.configure(), HalStatus::ok) << camera.last_error();
    ASSERT_EQ(camera.start(), HalStatus::ok);
    ASSERT_TRUE(camera.wait_buffered(3, 10.0));
    hal::ColorFrame frame;
    const int delivered[] = {0, 3, 5};
    for (const int k : delivered) {
      ASSERT_EQ(clock.set(1.0 + k / 20.0), HalStatus::ok);
      ASSERT_EQ(camera.read(frame), HalStatus::ok) << "frame " << k;
      EXPECT_EQ(pixel_bgr(frame, 0, 0), frame_bgr(k));
      EXPECT_EQ(frame.header.sequence, static_cast<std::uint64_t>(k + 1));
      EXPECT_EQ(frame.width, 32);
      EXPECT_NEAR(frame.header.stamp_s, 1.0 + k / 20.0, 1e-9);  // media time counts the dropped frames
    }
    EXPECT_EQ(camera.read(frame), HalStatus::no_data);
    EXPECT_TRUE(camera.end_of_stream());
    const OpenCvCameraStats stats = camera.stats();
    EXPECT_EQ(stats.decoded, 6u);
    EXPECT_EQ(stats.decode_errors, 2u);
    EXPECT_EQ(stats.size_mismatches, 1u);
    EXPECT_EQ(stats.skipped, 0u);
    // Every drop shows as a sequence gap.
    EXPECT_EQ(camera.counters().dropped, stats.decode_errors + stats.size_mismatches);
  }
}

TEST_F(OpenCvSequence, CorruptFirstFrameFailsConfigure) {
  opencv_test::write_bytes(dir_ / "g0.png", "definitely not a PNG");
  opencv_test::write_png(dir_ / "g1.png", 1);
  ManualClock clock;
  OpenCvCamera camera(clock, sequence_config(dir_ / "g%d.png", hal::PixelFormat::rgb8));
  EXPECT_EQ(camera.configure(), HalStatus::io_error);
  EXPECT_NE(camera.last_error().find("first frame cannot be decoded"), std::string::npos) << camera.last_error();
}

TEST_F(OpenCvSequence, MissingAndMalformedPatterns) {
  ManualClock clock;
  {
    OpenCvCamera camera(clock, sequence_config(dir_ / "none_%04d.png", hal::PixelFormat::rgb8));
    EXPECT_EQ(camera.configure(), HalStatus::io_error);
    EXPECT_NE(camera.last_error().find("no file matches"), std::string::npos) << camera.last_error();
    EXPECT_NE(camera.last_error().find("none_0000.png"), std::string::npos) << camera.last_error();
  }
  {
    OpenCvCamera camera(clock, sequence_config(dir_ / "frames.png", hal::PixelFormat::rgb8));
    EXPECT_EQ(camera.configure(), HalStatus::invalid_argument);
    EXPECT_NE(camera.last_error().find("no %d"), std::string::npos) << camera.last_error();
  }
  {
    OpenCvCamera camera(clock, sequence_config(dir_ / "f_%s_%n.png", hal::PixelFormat::rgb8));
    EXPECT_EQ(camera.configure(), HalStatus::invalid_argument);
    EXPECT_NE(camera.last_error().find("only %d"), std::string::npos) << camera.last_error();
  }
  {
    std::filesystem::create_directory(dir_ / "empty");
    OpenCvCamera camera(clock, sequence_config(dir_ / "empty", hal::PixelFormat::rgb8));
    EXPECT_EQ(camera.configure(), HalStatus::io_error);
    EXPECT_NE(camera.last_error().find("no image files"), std::string::npos) << camera.last_error();
  }
}

}  // namespace
}  // namespace pliant::drivers
