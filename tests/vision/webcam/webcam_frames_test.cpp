// Frame sources and the reader: patterns, globs, videos, memory; resampling; malformed input.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include <opencv2/videoio.hpp>

#include "pliant/vision/webcam_error.hpp"
#include "pliant/vision/webcam_frames.hpp"
#include "webcam_test_support.hpp"

namespace pliant::vision::webcam {
namespace {

using test::TempDir;

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// Runs `f`, expecting an InputError whose message contains `part` and is a single line.
template <typename F>
void expect_input_error(F&& f, const std::string& part) {
  try {
    f();
    ADD_FAILURE() << "no InputError; expected one containing '" << part << "'";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_TRUE(contains(what, part)) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
}

std::vector<int> taken(double fps, double rate, int frames) {
  FrameRateSampler sampler(fps, rate);
  std::vector<int> out;
  for (int i = 0; i < frames; ++i) {
    if (sampler.take(i)) out.push_back(i);
  }
  return out;
}

TEST(webcam_frames, SamplerTakesTheFrameNearestToEachTick) {
  EXPECT_EQ(taken(30, 10, 10), (std::vector<int>{0, 3, 6, 9}));
  EXPECT_EQ(taken(30, 0, 4), (std::vector<int>{0, 1, 2, 3}));
  EXPECT_EQ(taken(30, 30, 4), (std::vector<int>{0, 1, 2, 3}));
  EXPECT_EQ(taken(29.97, 30, 4), (std::vector<int>{0, 1, 2, 3}));  // a hair above: every frame
  // 25 -> 10 Hz: ticks at 0, 0.1, 0.2, ... s; frames every 0.04 s; nearest 0, 2 (0.08), 5, 7 (0.28), 10.
  EXPECT_EQ(taken(25, 10, 11), (std::vector<int>{0, 2, 5, 7, 10}));
  expect_input_error([] { FrameRateSampler(30, 60); }, "--rate 60 Hz is above the source's 30");
  expect_input_error([] { FrameRateSampler(30, -1); }, "--rate");
  expect_input_error([] { FrameRateSampler(30, std::nan("")); }, "--rate");
}

TEST(webcam_frames, PrintfPatternStartsAtZeroOrOneAndStopsAtTheFirstGap) {
  TempDir dir;
  const cv::Mat image = test::random_texture(16, 12, 1);
  for (int i : {1, 2, 3, 5}) test::write_png(dir / cv::format("f_%03d.png", i), image);
  const std::vector<std::string> files = expand_image_pattern(dir / "f_%03d.png");
  ASSERT_EQ(files.size(), 3u);
  EXPECT_EQ(files[0], dir / "f_001.png");
  EXPECT_EQ(files[2], dir / "f_003.png");
  test::write_png(dir / "f_000.png", image);
  EXPECT_EQ(expand_image_pattern(dir / "f_%03d.png").size(), 4u);
  // Unpadded numbers, and a pattern that matches nothing.
  test::write_png(dir / "g0.png", image);
  test::write_png(dir / "g1.png", image);
  EXPECT_EQ(expand_image_pattern(dir / "g%d.png").size(), 2u);
  expect_input_error([&] { expand_image_pattern(dir / "h_%04d.png"); }, "no file for number 0 or 1");
  // Not a pattern: a plain name (a video), two fields, an unknown conversion.
  EXPECT_TRUE(expand_image_pattern(dir / "video.avi").empty());
  EXPECT_TRUE(expand_image_pattern(dir / "a%d_%d.png").empty());
  EXPECT_TRUE(expand_image_pattern(dir / "a%s.png").empty());
}

TEST(webcam_frames, GlobIsSortedByName) {
  TempDir dir;
  const cv::Mat image = test::random_texture(16, 12, 1);
  for (const char* name : {"b.png", "a.png", "c.png"}) test::write_png(dir / name, image);
  const std::vector<std::string> files = expand_image_pattern(dir / "*.png");
  ASSERT_EQ(files.size(), 3u);
  EXPECT_EQ(files[0], dir / "a.png");
  EXPECT_EQ(files[2], dir / "c.png");
  expect_input_error([&] { expand_image_pattern(dir / "*.jpg"); }, "no file matches");
}

TEST(webcam_frames, ImageSequenceIsReadInOrderAtItsRate) {
  TempDir dir;
  for (int i = 0; i < 4; ++i)
    test::write_png(dir / cv::format("f_%02d.png", i), test::random_texture(20, 10, static_cast<unsigned>(i)));
  expect_input_error([&] { open_frame_source(dir / "f_%02d.png", 0); }, "needs its frame rate (--fps)");
  auto source = open_frame_source(dir / "f_%02d.png", 0, 30);
  EXPECT_DOUBLE_EQ(source->fps(), 30);
  EXPECT_EQ(source->frame_count(), 4);
  FrameReader reader(*source, 15);
  EXPECT_EQ(reader.expected_frames(), 2);
  GreyFrame frame;
  ASSERT_TRUE(reader.next(frame));
  EXPECT_EQ(frame.source_index, 0);
  EXPECT_EQ(frame.grey.type(), CV_8UC1);
  EXPECT_EQ(frame.grey.size(), cv::Size(20, 10));
  ASSERT_TRUE(reader.next(frame));
  EXPECT_EQ(frame.source_index, 2);
  EXPECT_DOUBLE_EQ(frame.t_s, 2.0 / 30);
  EXPECT_EQ(frame.label, dir / "f_02.png");
  EXPECT_FALSE(reader.next(frame));
}

TEST(webcam_frames, FrameOfAnotherSizeIsRefusedNamingIt) {
  TempDir dir;
  test::write_png(dir / "f_0.png", test::random_texture(32, 24, 1));
  test::write_png(dir / "f_1.png", test::random_texture(32, 24, 2));
  test::write_png(dir / "f_2.png", test::random_texture(30, 24, 3));
  auto source = open_frame_source(dir / "f_%d.png", 10);
  FrameReader reader(*source, 0);
  GreyFrame frame;
  ASSERT_TRUE(reader.next(frame));
  ASSERT_TRUE(reader.next(frame));
  expect_input_error([&] { reader.next(frame); }, dir / "f_2.png" + ": 30x24, the first frame is 32x24");
}

TEST(webcam_frames, DamagedOrUnsupportedImagesAreRefusedNamingThem) {
  TempDir dir;
  test::write_png(dir / "f_0.png", test::random_texture(32, 24, 1));
  test::write_bytes(dir / "f_1.png", "\x89PNG\r\n\x1a\nnot really a png");
  auto source = open_frame_source(dir / "f_%d.png", 10);
  FrameReader reader(*source, 0);
  GreyFrame frame;
  ASSERT_TRUE(reader.next(frame));
  expect_input_error([&] { reader.next(frame); }, dir / "f_1.png" + ": cannot read the image");

  // A 16-bit image is not a camera frame we track.
  cv::Mat deep(24, 32, CV_16UC1, cv::Scalar(1000));
  test::write_png(dir / "g_0.png", deep);
  auto deep_source = open_frame_source(dir / "g_%d.png", 10);
  FrameReader deep_reader(*deep_source, 0);
  expect_input_error([&] { deep_reader.next(frame); }, "not an 8-bit image");
}

TEST(webcam_frames, UnreadableVideosAreRefused) {
  TempDir dir;
  expect_input_error([&] { open_frame_source(dir / "missing.avi", 0); }, "missing.avi: no such file");
  expect_input_error([&] { open_frame_source(dir.path().string(), 0); }, "is a directory");
  test::write_bytes(dir / "garbage.avi", std::string(4096, '\x5a'));
  expect_input_error([&] { open_frame_source(dir / "garbage.avi", 0); }, "garbage.avi: cannot open the video");
  test::write_bytes(dir / "empty.mp4", "");
  expect_input_error([&] { open_frame_source(dir / "empty.mp4", 0); }, "empty.mp4: cannot open the video");
  expect_input_error([&] { open_frame_source("", 0); }, "no video or image pattern");
  expect_input_error([&] { open_frame_source(dir / "x.avi", -3); }, "--fps");
}

TEST(webcam_frames, VideoFileIsReadFrameByFrame) {
  TempDir dir;
  const std::string path = dir / "clip.avi";
  cv::VideoWriter writer(path, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 20, cv::Size(64, 48), true);
  ASSERT_TRUE(writer.isOpened());
  const cv::Mat texture = test::random_texture(64, 48, 4);
  cv::Mat colour;
  for (int i = 0; i < 6; ++i) {
    cv::cvtColor(test::shifted(texture, i, 0), colour, cv::COLOR_GRAY2BGR);
    writer.write(colour);
  }
  writer.release();
  auto source = open_frame_source(path, 0);
  EXPECT_NEAR(source->fps(), 20, 1e-6);
  FrameReader reader(*source, 10);
  GreyFrame frame;
  std::vector<int> indices;
  while (reader.next(frame)) {
    EXPECT_EQ(frame.grey.size(), cv::Size(64, 48));
    indices.push_back(frame.source_index);
  }
  EXPECT_EQ(indices, (std::vector<int>{0, 2, 4}));
  // --fps overrides the container's rate.
  EXPECT_DOUBLE_EQ(open_frame_source(path, 5)->fps(), 5);
}

TEST(webcam_frames, MemoryFramesAndConversions) {
  const cv::Mat grey = test::random_texture(8, 6, 1);
  cv::Mat bgr, bgra;
  cv::cvtColor(grey, bgr, cv::COLOR_GRAY2BGR);
  cv::cvtColor(grey, bgra, cv::COLOR_GRAY2BGRA);
  MemoryFrameSource source({grey, bgr, bgra, cv::Mat(6, 8, CV_8UC2, cv::Scalar(1, 2))}, 10);
  FrameReader reader(source, 0);
  GreyFrame frame;
  for (int i = 0; i < 3; ++i) {
    ASSERT_TRUE(reader.next(frame));
    EXPECT_EQ(cv::norm(frame.grey, grey, cv::NORM_INF), 0) << i;
  }
  expect_input_error([&] { reader.next(frame); }, "2 channels");
  expect_input_error([] { MemoryFrameSource({}, 0); }, "frame rate");
  MemoryFrameSource empty_frame({cv::Mat()}, 10);
  FrameReader empty_reader(empty_frame, 0);
  expect_input_error([&] { empty_reader.next(frame); }, "empty frame");
}

}  // namespace
}  // namespace pliant::vision::webcam
