// `pliant record`'s writer (host/cli/record_writer.hpp, record_media.hpp) fed HAL samples and
// frames directly: what it keeps, what it drops and counts (non-finite, out of order, fault
// flagged, queue full, another frame size), and what the media files hold.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include "../support/temp_dir.hpp"
#include "record_media.hpp"
#include "record_particles.hpp"
#include "record_writer.hpp"

namespace pliant::cli {
namespace {

namespace fs = std::filesystem;

class TempDir : public test_support::TempDir {
 public:
  TempDir() : test_support::TempDir("pliant_record_writer_") {}
};

std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

hal::WrenchReading wrench(double stamp, double fx, std::uint32_t bits = 0) {
  hal::WrenchReading r;
  r.header.stamp_s = stamp;
  r.header.status_bits = bits;
  const double values[6] = {fx, 2, 3, 0.1, 0.2, 0.3};
  for (int i = 0; i < 6; ++i) r.wrench[i] = values[i];
  return r;
}

hal::GripperReading gripper(double stamp, double width) {
  hal::GripperReading r;
  r.header.stamp_s = stamp;
  r.header.status_bits = hal::kGripperActivated;
  r.width_m = width;
  r.current_a = 0.25;
  return r;  // force_n and target_width_m stay NaN, as a Robotiq reports them
}

// A colour frame over `bytes` (rows of `stride` bytes, the pixels filled with one colour).
struct TestFrame {
  std::vector<std::uint8_t> bytes;
  hal::ColorFrame frame;
  TestFrame(int width, int height, hal::PixelFormat format, const std::uint8_t colour[3], double stamp, int pad = 5) {
    const int channels = hal::pixel_bytes(format);
    const int stride = width * channels + pad;
    bytes.assign(static_cast<std::size_t>(stride * height), 0xee);  // padding must not show
    for (int y = 0; y < height; ++y) {
      for (int x = 0; x < width; ++x) {
        for (int c = 0; c < channels; ++c) bytes[static_cast<std::size_t>(y * stride + x * channels + c)] = colour[c];
      }
    }
    frame.header.stamp_s = stamp;
    frame.width = width;
    frame.height = height;
    frame.stride_bytes = stride;
    frame.format = format;
    frame.data = bytes.data();
  }
};

TEST(RecordWriter, SamplesOnTheRecordingClockAndDrops) {
  TempDir dir;
  RecordWriter w(dir.path().string(), 100.0, false);
  EXPECT_TRUE(w.add_wrench(wrench(100.25, 1.0)));
  EXPECT_FALSE(w.add_wrench(wrench(kNaN, 1.0)));                        // stamp
  EXPECT_FALSE(w.add_wrench(wrench(100.5, kNaN)));                      // value
  EXPECT_FALSE(w.add_wrench(wrench(100.25, 1.0)));                      // same stamp
  EXPECT_FALSE(w.add_wrench(wrench(100.125, 1.0)));                     // earlier
  EXPECT_FALSE(w.add_wrench(wrench(100.5, 1.0, hal::kFtAdcHigh)));      // the sensor says "do not trust"
  EXPECT_TRUE(w.add_wrench(wrench(100.5, -4.0, hal::kFtCanBusError)));  // degraded transport only: kept
  ASSERT_EQ(w.wrench().size(), 2u);
  EXPECT_DOUBLE_EQ(w.wrench()[0].t_s, 0.25);
  EXPECT_DOUBLE_EQ(w.wrench()[1].t_s, 0.5);
  EXPECT_DOUBLE_EQ(w.wrench()[1].force_n[0], -4.0);
  EXPECT_DOUBLE_EQ(w.wrench()[1].torque_nm[2], 0.3);
  const StreamCounters& c = w.wrench_counters();
  EXPECT_EQ(c.recorded, 2u);
  EXPECT_EQ(c.non_finite, 2u);
  EXPECT_EQ(c.out_of_order, 2u);
  EXPECT_EQ(c.fault_flagged, 1u);
  EXPECT_EQ(c.dropped(), 5u);

  EXPECT_TRUE(w.add_gripper(gripper(100.0, 0.08)));
  EXPECT_FALSE(w.add_gripper(gripper(100.1, kNaN)));
  EXPECT_FALSE(w.add_gripper(gripper(std::numeric_limits<double>::infinity(), 0.07)));
  EXPECT_FALSE(w.add_gripper(gripper(99.0, 0.07)));
  hal::GripperReading faulted = gripper(100.25, 0.07);
  faulted.header.status_bits |= 0x0eu << hal::kGripperFaultCodeShift;
  EXPECT_TRUE(w.add_gripper(faulted));  // a fault code: the width is still measured
  EXPECT_EQ(w.gripper_counters().recorded, 2u);
  EXPECT_EQ(w.gripper_counters().non_finite, 2u);
  EXPECT_EQ(w.gripper_counters().out_of_order, 1u);

  w.finish();
  const std::vector<std::string> lines = lines_of(read_text(dir.path() / "gripper_state.csv"));
  ASSERT_EQ(lines.size(), 3u);
  EXPECT_EQ(lines[0], "t,width_m,target_width_m,force_n,current_a,status_bits");
  EXPECT_EQ(lines[1], "0,0.08,nan,nan,0.25,1");
  EXPECT_EQ(lines[2], "0.25,0.07,nan,nan,0.25,3585");
  EXPECT_EQ(w.files().at("gripper_state"), "gripper_state.csv");
  EXPECT_EQ(w.files().count("color_video"), 0u);
  EXPECT_THROW(w.finish(), std::logic_error);

  // The jaws of those rows.
  const host::Recording jaws = jaw_recording(w.gripper(), "r");
  ASSERT_EQ(jaws.frame_count(), 2);
  EXPECT_DOUBLE_EQ(jaws.position(1, 1, 0), 0.07);
  EXPECT_EQ(jaws.position(1, 0, 0), 0.0);
  EXPECT_THROW(jaw_recording({}, "r"), std::runtime_error);
}

TEST(RecordWriter, ColourVideoAndFrameTimes) {
  TempDir dir;
  RecordWriter w(dir.path().string(), 10.0, true);
  const std::uint8_t red_rgb[3] = {255, 0, 0};
  const std::uint8_t red_bgr[3] = {0, 0, 255};
  const std::uint8_t grey[3] = {128, 0, 0};
  // 12 frames at 25 Hz in three formats; a fault-flagged one, a repeated stamp and a frame of
  // another size in between.
  for (int k = 0; k < 12; ++k) {
    const double stamp = 10.0 + 0.04 * k;
    const hal::PixelFormat format = k % 3 == 0   ? hal::PixelFormat::rgb8
                                    : k % 3 == 1 ? hal::PixelFormat::bgr8
                                                 : hal::PixelFormat::mono8;
    const std::uint8_t* colour = k % 3 == 0 ? red_rgb : k % 3 == 1 ? red_bgr : grey;
    TestFrame f(32, 24, format, colour, stamp);
    EXPECT_TRUE(w.add_color(f.frame));
    if (k == 5) {
      TestFrame again(32, 24, format, colour, stamp);
      EXPECT_FALSE(w.add_color(again.frame));  // same stamp
      TestFrame bad(32, 24, format, colour, stamp + 0.01);
      bad.frame.header.status_bits = hal::kFrameDeviceFault;
      EXPECT_FALSE(w.add_color(bad.frame));
      TestFrame other(16, 24, format, colour, stamp + 0.02);
      EXPECT_TRUE(w.add_color(other.frame));  // dropped by the encoder: another size
    }
  }
  EXPECT_EQ(w.media_error(), "");
  w.finish();
  EXPECT_EQ(w.color_counters().recorded, 13u);
  EXPECT_EQ(w.color_counters().out_of_order, 1u);
  EXPECT_EQ(w.color_counters().fault_flagged, 1u);
  EXPECT_EQ(w.color_size_mismatches(), 1u);
  ASSERT_EQ(w.color_times().size(), 12u);
  EXPECT_NEAR(w.color_fps(), 25.0, 1e-9);
  EXPECT_EQ(w.color_width(), 32);
  EXPECT_EQ(w.color_height(), 24);
  const std::vector<std::string> lines = lines_of(read_text(dir.path() / "color_frames.csv"));
  ASSERT_EQ(lines.size(), 13u);
  EXPECT_EQ(lines[0], "index,t");
  for (int k = 0; k < 12; ++k) {
    const std::string row = lines[static_cast<std::size_t>(k) + 1];
    EXPECT_EQ(row.substr(0, row.find(',')), std::to_string(k));
    EXPECT_NEAR(std::stod(row.substr(row.find(',') + 1)), 0.04 * k, 1e-9);
  }
  // color.avi: 12 frames; red stays red whatever format it came in (BGR after decoding).
  cv::VideoCapture video((dir.path() / "color.avi").string());
  ASSERT_TRUE(video.isOpened());
  EXPECT_NEAR(video.get(cv::CAP_PROP_FPS), 25.0, 0.01);
  int k = 0;
  for (cv::Mat image; video.read(image); ++k) {
    ASSERT_EQ(image.size(), cv::Size(32, 24));
    const cv::Vec3b centre = image.at<cv::Vec3b>(12, 16);
    if (k % 3 == 2) {
      EXPECT_NEAR(centre[0], 128, 12);
      EXPECT_NEAR(centre[2], 128, 12);
    } else {
      EXPECT_LT(centre[0], 30) << "frame " << k;
      EXPECT_GT(centre[2], 220) << "frame " << k;
    }
  }
  EXPECT_EQ(k, 12);
  EXPECT_EQ(w.files().at("color_video"), "color.avi");
  EXPECT_EQ(w.files().at("color_frames"), "color_frames.csv");
}

TEST(RecordWriter, DepthImagesAreLossless) {
  TempDir dir;
  RecordWriter w(dir.path().string(), 0.0, true);
  const int width = 20, height = 10, stride_px = 23;
  std::vector<std::uint16_t> pixels(static_cast<std::size_t>(stride_px * height), 0xbeef);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x)
      pixels[static_cast<std::size_t>(y * stride_px + x)] = static_cast<std::uint16_t>(1000 * y + x);
  }
  hal::DepthFrame frame;
  frame.width = width;
  frame.height = height;
  frame.stride_bytes = 2 * stride_px;
  frame.data = pixels.data();
  frame.depth_scale_m = 1e-4;
  frame.header.stamp_s = 0.5;
  EXPECT_TRUE(w.add_depth(frame));
  frame.header.stamp_s = 0.5;
  EXPECT_FALSE(w.add_depth(frame));  // same stamp
  frame.header.stamp_s = 0.6;
  frame.fx = 500;
  frame.fy = 501;
  frame.cx = 9.5;
  frame.cy = 4.5;
  EXPECT_TRUE(w.add_depth(frame));
  w.finish();
  EXPECT_EQ(w.depth_frame_count(), 2u);
  const std::vector<std::string> lines = lines_of(read_text(dir.path() / "depth_frames.csv"));
  ASSERT_EQ(lines.size(), 3u);
  EXPECT_EQ(lines[0], "index,t,file,depth_scale_m,fx,fy,cx,cy");
  EXPECT_EQ(lines[1], "0,0.5,depth/000000.png,1e-04,nan,nan,nan,nan");
  EXPECT_EQ(lines[2], "1,0.6,depth/000001.png,1e-04,500,501,9.5,4.5");
  const cv::Mat png = cv::imread((dir.path() / "depth/000001.png").string(), cv::IMREAD_UNCHANGED);
  ASSERT_EQ(png.type(), CV_16UC1);
  ASSERT_EQ(png.size(), cv::Size(width, height));
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) EXPECT_EQ(png.at<std::uint16_t>(y, x), 1000 * y + x);
  }
  EXPECT_EQ(w.files().at("depth_frames"), "depth_frames.csv");
  EXPECT_FALSE(fs::exists(dir.path() / "color.avi"));
}

TEST(MediaWriter, QueueFullDropsAndAnUnwritableDirectoryFails) {
  TempDir dir;
  {
    MediaWriter small(dir.path().string(), 100);  // less than one 32 x 24 frame
    const std::uint8_t colour[3] = {1, 2, 3};
    TestFrame f(32, 24, hal::PixelFormat::bgr8, colour, 0.0);
    EXPECT_FALSE(small.push_color(f.frame, 0.0));
    hal::ColorFrame empty;
    EXPECT_FALSE(small.push_color(empty, 0.0));  // no data
    small.finish();
    EXPECT_TRUE(small.color_times().empty());
  }
  // Depth under a regular file (no directory can be made there): the first error stops the
  // encoder and is reported.
  std::ofstream(dir.path() / "blocker") << "a file";
  MediaWriter broken((dir.path() / "blocker").string());
  std::vector<std::uint16_t> pixels(16, 7);
  hal::DepthFrame frame;
  frame.width = 4;
  frame.height = 4;
  frame.stride_bytes = 8;
  frame.data = pixels.data();
  ASSERT_TRUE(broken.push_depth(frame, 0.0));
  EXPECT_THROW(broken.finish(), std::runtime_error);
  EXPECT_NE(broken.error(), "");
}

}  // namespace
}  // namespace pliant::cli
