// The file readers every reader of files in pliant shares (image_files.hpp, file_readers.hpp):
// the forms of a sequence location, their listings and messages, malformed and missing input,
// videos opened and refused, images decoded as stored or as 8-bit colour; and a glob through the
// camera.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "opencv_test_media.hpp"
#include "pliant/drivers/opencv/file_readers.hpp"
#include "pliant/drivers/opencv/image_files.hpp"
#include "pliant/drivers/opencv/opencv_camera.hpp"
#include "support/temp_dir.hpp"

namespace pliant::drivers::opencv_files {
namespace {

using hal::HalStatus;

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

std::vector<std::string> listed(const std::string& location, int first_index = -1) {
  std::vector<std::string> files;
  FileError error;
  EXPECT_TRUE(list_image_sequence(location, sequence_form(location), first_index, files, error))
      << location << ": " << error.message;
  return files;
}

FileError refused(const std::string& location, int first_index = -1) {
  std::vector<std::string> files{"stale"};
  FileError error;
  EXPECT_FALSE(list_image_sequence(location, sequence_form(location), first_index, files, error)) << location;
  EXPECT_TRUE(files.empty()) << location;
  EXPECT_EQ(error.message.find('\n'), std::string::npos) << error.message;
  return error;
}

class OpenCvFileReaders : public ::testing::Test {
 protected:
  test_support::TempDir dir_{"pliant_opencv_files_"};
};

TEST(OpenCvFileRates, OneRuleForEveryRate) {
  EXPECT_TRUE(valid_file_rate(30));
  EXPECT_TRUE(valid_file_rate(kMaxFileRateHz));
  EXPECT_FALSE(valid_file_rate(0));
  EXPECT_FALSE(valid_file_rate(-1));
  EXPECT_FALSE(valid_file_rate(kMaxFileRateHz * 1.001));
  EXPECT_FALSE(valid_file_rate(std::nan("")));
  EXPECT_FALSE(valid_file_rate(HUGE_VAL));
}

TEST_F(OpenCvFileReaders, FormsOfALocation) {
  EXPECT_EQ(sequence_form(dir_.path().string()), SequenceForm::directory);
  EXPECT_EQ(sequence_form(dir_ / "f_%03d.png"), SequenceForm::pattern);
  EXPECT_EQ(sequence_form(dir_ / "100%%_%u.png"), SequenceForm::pattern);
  EXPECT_EQ(sequence_form(dir_ / "*.png"), SequenceForm::glob);
  EXPECT_EQ(sequence_form(dir_ / "f_[0-9].png"), SequenceForm::glob);
  EXPECT_EQ(sequence_form(dir_ / "a%d_%d*.png"), SequenceForm::glob);  // not one conversion, but a glob
  EXPECT_EQ(sequence_form(dir_ / "clip.avi"), SequenceForm::not_a_sequence);
  EXPECT_EQ(sequence_form(dir_ / "a%s.png"), SequenceForm::not_a_sequence);
  EXPECT_EQ(sequence_form(""), SequenceForm::not_a_sequence);
}

TEST_F(OpenCvFileReaders, PatternFromZeroOrOneOrTheGivenIndexToTheFirstGap) {
  for (int k : {1, 2, 3, 5}) opencv_test::write_png(dir_ / cv::format("f_%03d.png", k), k);
  std::vector<std::string> files = listed(dir_ / "f_%03d.png");
  ASSERT_EQ(files.size(), 3u);
  EXPECT_EQ(files.front(), dir_ / "f_001.png");
  EXPECT_EQ(files.back(), dir_ / "f_003.png");
  EXPECT_EQ(listed(dir_ / "f_%03d.png", 5), std::vector<std::string>{dir_ / "f_005.png"});
  opencv_test::write_png(dir_ / "f_000.png", 0);
  EXPECT_EQ(listed(dir_ / "f_%03d.png").size(), 4u);

  const FileError none = refused(dir_ / "g_%02d.png");
  EXPECT_EQ(none.status, HalStatus::io_error);
  EXPECT_TRUE(contains(none.message, "image sequence " + dir_ / "g_%02d.png" + ": no file matches")) << none.message;
  EXPECT_TRUE(contains(none.message, "no file for number 0 or 1")) << none.message;
  EXPECT_TRUE(contains(none.message, dir_ / "g_00.png")) << none.message;
  EXPECT_TRUE(contains(none.message, dir_ / "g_01.png")) << none.message;
  const FileError first = refused(dir_ / "f_%03d.png", 4);
  EXPECT_TRUE(contains(first.message, "no file " + dir_ / "f_004.png")) << first.message;
}

TEST_F(OpenCvFileReaders, GlobInByteOrderOfRegularFiles) {
  for (const char* name : {"b.png", "a.png", "c10.png", "c9.png"}) opencv_test::write_png(dir_ / name, 0);
  std::filesystem::create_directory(dir_ / "d.png");  // a directory named like an image
  const std::vector<std::string> files = listed(dir_ / "*.png");
  const std::vector<std::string> want = {dir_ / "a.png", dir_ / "b.png", dir_ / "c10.png", dir_ / "c9.png"};
  EXPECT_EQ(files, want);
  EXPECT_TRUE(contains(refused(dir_ / "*.jpg").message, "image sequence " + dir_ / "*.jpg" + ": no file matches"));
  EXPECT_TRUE(contains(refused(dir_ / "nowhere/*/*.png").message, "no file matches"));
  EXPECT_TRUE(contains(refused(dir_ / "[unclosed.png").message, "no file matches"));
}

TEST_F(OpenCvFileReaders, DirectoryInNaturalOrderOfImageFiles) {
  for (const char* name : {"10.png", "2.png", "1.JPG"}) opencv_test::write_png(dir_ / name, 0);
  opencv_test::write_bytes(dir_ / "notes.txt", "not an image");
  EXPECT_EQ(listed(dir_.path().string()), (std::vector<std::string>{dir_ / "1.JPG", dir_ / "2.png", dir_ / "10.png"}));
  std::filesystem::create_directory(dir_ / "empty");
  const FileError empty = refused(dir_ / "empty");
  EXPECT_TRUE(contains(empty.message, "image directory " + dir_ / "empty" + ": no image files")) << empty.message;
}

TEST_F(OpenCvFileReaders, MalformedPatternsAreInvalidArguments) {
  for (const std::string& location : {dir_ / "frames.png", dir_ / "f_%s.png", dir_ / "f_%123d.png", std::string()}) {
    const FileError error = refused(location);
    EXPECT_EQ(error.status, HalStatus::invalid_argument) << location;
    EXPECT_TRUE(contains(error.message, "image pattern: ")) << error.message;
  }
}

TEST_F(OpenCvFileReaders, VideosOpenedAndRefusedWithOneMessageEach) {
  const std::string clip = dir_ / "clip.avi";
  opencv_test::write_video(clip, 5, 25);
  FileError error;
  std::unique_ptr<VideoFile> video = VideoFile::open(clip, error);
  ASSERT_NE(video, nullptr) << error.message;
  EXPECT_NEAR(video->stated_fps(), 25, 1e-6);
  EXPECT_EQ(video->path(), clip);
  cv::Mat image;
  int frames = 0;
  while (video->read(image)) {
    EXPECT_EQ(image.size(), cv::Size(64, 48));
    ++frames;
  }
  EXPECT_EQ(frames, 5);

  const auto message = [](const std::string& path) {
    FileError e;
    EXPECT_EQ(VideoFile::open(path, e), nullptr) << path;
    EXPECT_EQ(e.status, HalStatus::io_error) << path;
    EXPECT_EQ(e.message.find('\n'), std::string::npos) << e.message;
    return e.message;
  };
  EXPECT_EQ(message(dir_ / "missing.avi"), "video file " + dir_ / "missing.avi" + ": no such file");
  EXPECT_EQ(message(dir_.path().string()),
            "video file " + dir_.path().string() + ": is a directory, not a regular file");
  opencv_test::write_bytes(dir_ / "garbage.avi", std::string(4096, '\x5a'));
  EXPECT_TRUE(contains(message(dir_ / "garbage.avi"), "garbage.avi: cannot open the video: OpenCV cannot decode it"));
  opencv_test::write_bytes(dir_ / "empty.mp4", "");
  EXPECT_TRUE(contains(message(dir_ / "empty.mp4"), "empty.mp4: cannot open the video"));
  EXPECT_TRUE(contains(message(""), "no such file"));
}

TEST_F(OpenCvFileReaders, ImagesAsStoredOrAsColour) {
  const cv::Mat deep(6, 8, CV_16UC1, cv::Scalar(4000));
  ASSERT_TRUE(cv::imwrite(dir_ / "deep.png", deep));
  const cv::Mat stored = read_image(dir_ / "deep.png", ImageDecoding::as_stored);
  EXPECT_EQ(stored.type(), CV_16UC1);
  const cv::Mat colour = read_image(dir_ / "deep.png", ImageDecoding::colour8);
  EXPECT_EQ(colour.type(), CV_8UC3);
  EXPECT_EQ(colour.size(), cv::Size(8, 6));
  opencv_test::write_bytes(dir_ / "broken.png", "\x89PNG\r\n\x1a\nbroken");
  EXPECT_TRUE(read_image(dir_ / "broken.png", ImageDecoding::as_stored).empty());
  EXPECT_TRUE(read_image(dir_ / "missing.png", ImageDecoding::colour8).empty());
  EXPECT_TRUE(read_image(dir_.path().string(), ImageDecoding::colour8).empty());
}

TEST_F(OpenCvFileReaders, CameraPlaysAGlob) {
  for (int k = 0; k < 3; ++k) opencv_test::write_png(dir_ / cv::format("shot_%c.png", 'a' + k), k);
  hal::ManualClock clock;
  OpenCvCameraConfig config;
  config.source = OpenCvSource::image_sequence;
  config.location = dir_ / "shot_*.png";
  config.playback = OpenCvPlayback::stepped;
  config.format = hal::PixelFormat::bgr8;
  OpenCvCamera camera(clock, config);
  ASSERT_EQ(camera.configure(), HalStatus::ok) << camera.last_error();
  ASSERT_EQ(camera.start(), HalStatus::ok);
  hal::ColorFrame frame;
  for (int k = 0; k < 3; ++k) {
    ASSERT_EQ(camera.read(frame), HalStatus::ok) << k;
    const cv::Vec3b bgr(frame.data[0], frame.data[1], frame.data[2]);
    EXPECT_EQ(opencv_test::frame_index_of(bgr, 3, 2), k);
  }
  EXPECT_NE(camera.read(frame), HalStatus::ok);
  EXPECT_TRUE(camera.end_of_stream());

  config.location = dir_ / "other_*.png";
  OpenCvCamera none(clock, config);
  EXPECT_EQ(none.configure(), HalStatus::io_error);
  EXPECT_TRUE(contains(none.last_error(), "no file matches")) << none.last_error();
}

}  // namespace
}  // namespace pliant::drivers::opencv_files
