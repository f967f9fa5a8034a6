// drivers/openni2 Openni2Camera on devices: Debian's DummyDevice opened by URI (a synthetic
// 320x240 millimetre stream with no field of view), "any" without a camera, unknown URIs, and
// where OpenNI2 looks for its drivers.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include "pliant/drivers/openni2/openni2_camera.hpp"
#include "pliant/hal/clock.hpp"

namespace {

using namespace pliant::drivers::openni2;
using pliant::hal::DepthFrame;
using pliant::hal::HalStatus;

// The Dummy driver ships in Debian's libopenni2-0; say exactly what is missing otherwise.
bool dummy_driver_present(std::string& why) {
  const std::string directory = openni2_driver_directory();
  if (directory.empty()) {
    why = "cannot locate the loaded libOpenNI2.so (dladdr failed)";
    return false;
  }
  std::error_code ec;
  if (!std::filesystem::exists(directory + "/libDummyDevice.so.0", ec) &&
      !std::filesystem::exists(directory + "/libDummyDevice.so", ec)) {
    why = "OpenNI2's DummyDevice driver is not in " + directory + " (Debian package libopenni2-0 ships it there)";
    return false;
  }
  return true;
}

Openni2CameraConfig dummy_config() {
  Openni2CameraConfig config;
  config.source = Openni2Source::device;
  config.location = "Dummy";
  return config;
}

// Reads until `count` frames arrived (the Dummy produces one every 33 ms), at most 20 s.
std::vector<DepthFrame> read_frames(Openni2Camera& camera, int count, std::vector<std::uint16_t>* top_row = nullptr) {
  std::vector<DepthFrame> frames;
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (static_cast<int>(frames.size()) < count && std::chrono::steady_clock::now() < give_up) {
    DepthFrame frame;
    const HalStatus status = camera.read(frame);
    if (status == HalStatus::ok) {
      frames.push_back(frame);
      if (top_row != nullptr) top_row->assign(frame.data, frame.data + frame.width);
    } else {
      EXPECT_EQ(status, HalStatus::no_data);
      std::this_thread::sleep_for(std::chrono::milliseconds(3));
    }
  }
  return frames;
}

TEST(Openni2Device, DriverDirectoryIsNextToTheLibrary) {
  const std::string directory = openni2_driver_directory();
  ASSERT_FALSE(directory.empty());
  EXPECT_NE(directory.find("OpenNI2/Drivers"), std::string::npos) << directory;
  std::string why;
  if (!dummy_driver_present(why)) GTEST_SKIP() << why;
  EXPECT_TRUE(std::filesystem::is_directory(directory)) << directory;
}

TEST(Openni2Device, DummyByUriStreamsWithoutAFieldOfView) {
  std::string why;
  if (!dummy_driver_present(why)) GTEST_SKIP() << why;
  pliant::hal::SteadyClock clock;
  Openni2Camera camera(clock, dummy_config());
  ASSERT_EQ(camera.configure(), HalStatus::ok) << camera.last_error();
  EXPECT_EQ(camera.width(), 320);
  EXPECT_EQ(camera.height(), 240);
  const Openni2CameraStats stats = camera.stats();
  EXPECT_EQ(stats.intrinsics_source, IntrinsicsSource::none) << "the Dummy reports no field of view";
  EXPECT_FALSE(fov_is_valid(stats.hfov_rad, stats.vfov_rad));
  EXPECT_TRUE(std::isnan(camera.intrinsics().fx));

  ASSERT_EQ(camera.start(), HalStatus::ok);
  std::vector<std::uint16_t> top_row;
  const std::vector<DepthFrame> frames = read_frames(camera, 3, &top_row);
  ASSERT_EQ(frames.size(), 3u) << "the Dummy did not deliver 3 frames in 20 s";
  for (std::size_t i = 0; i < frames.size(); ++i) {
    EXPECT_EQ(frames[i].width, 320);
    EXPECT_EQ(frames[i].height, 240);
    EXPECT_DOUBLE_EQ(frames[i].depth_scale_m, 1e-3);
    EXPECT_TRUE(std::isnan(frames[i].fx));
    if (i > 0) {
      EXPECT_GT(frames[i].header.sequence, frames[i - 1].header.sequence);
      EXPECT_GE(frames[i].header.stamp_s, frames[i - 1].header.stamp_s);
    }
    EXPECT_LE(frames[i].header.stamp_s, clock.now_s());
  }
  EXPECT_EQ(frames.front().header.sequence, 1u) << "devices count from 1";
  // The Dummy paints its top row at 2000 mm.
  for (std::uint16_t d : top_row) EXPECT_EQ(d, 2000);
  EXPECT_FALSE(camera.end_of_stream());
  EXPECT_EQ(camera.stop(), HalStatus::ok);
  EXPECT_EQ(camera.cleanup(), HalStatus::ok);
}

TEST(Openni2Device, DummyTakesConfiguredIntrinsics) {
  std::string why;
  if (!dummy_driver_present(why)) GTEST_SKIP() << why;
  pliant::hal::SteadyClock clock;
  Openni2CameraConfig config = dummy_config();
  config.fallback_intrinsics = DepthIntrinsics{290, 291, 159.5, 119.5, 320, 240};
  Openni2Camera camera(clock, config);
  ASSERT_EQ(camera.configure(), HalStatus::ok) << camera.last_error();
  EXPECT_EQ(camera.stats().intrinsics_source, IntrinsicsSource::configured);
  ASSERT_EQ(camera.start(), HalStatus::ok);
  const std::vector<DepthFrame> frames = read_frames(camera, 1);
  ASSERT_EQ(frames.size(), 1u);
  EXPECT_DOUBLE_EQ(frames[0].fx, 290);
  EXPECT_DOUBLE_EQ(frames[0].fy, 291);
  EXPECT_DOUBLE_EQ(frames[0].cx, 159.5);
  std::vector<double> xyz(320 * 240 * 3);
  EXPECT_EQ(depth_to_points(frames[0], xyz.data(), 320 * 240).status, PointsStatus::ok);
  EXPECT_EQ(camera.stop(), HalStatus::ok);
  EXPECT_EQ(camera.cleanup(), HalStatus::ok);

  // Intrinsics for another image size are refused.
  config.fallback_intrinsics = DepthIntrinsics{500, 500, 319.5, 239.5, 640, 480};
  Openni2Camera wrong(clock, config);
  EXPECT_EQ(wrong.configure(), HalStatus::invalid_argument);
  EXPECT_NE(wrong.last_error().find("640x480"), std::string::npos) << wrong.last_error();
}

TEST(Openni2Device, DummyRefusesAModeItDoesNotHave) {
  std::string why;
  if (!dummy_driver_present(why)) GTEST_SKIP() << why;
  pliant::hal::SteadyClock clock;
  Openni2CameraConfig config = dummy_config();
  config.width = 640;
  config.height = 480;
  Openni2Camera camera(clock, config);
  EXPECT_EQ(camera.configure(), HalStatus::unsupported);
  EXPECT_NE(camera.last_error().find("640x480"), std::string::npos) << camera.last_error();
  // Asking for the mode it has is fine (nothing to change).
  config.width = 320;
  config.height = 240;
  config.fps = 30;
  Openni2Camera same(clock, config);
  EXPECT_EQ(same.configure(), HalStatus::ok) << same.last_error();
  EXPECT_EQ(same.cleanup(), HalStatus::ok);
}

TEST(Openni2Device, StopRightAfterStartIsSafe) {
  std::string why;
  if (!dummy_driver_present(why)) GTEST_SKIP() << why;
  pliant::hal::SteadyClock clock;
  for (int cycle = 0; cycle < 3; ++cycle) {
    Openni2Camera camera(clock, dummy_config());
    ASSERT_EQ(camera.configure(), HalStatus::ok) << camera.last_error();
    ASSERT_EQ(camera.start(), HalStatus::ok);
    EXPECT_EQ(camera.stop(), HalStatus::ok);
    EXPECT_EQ(camera.cleanup(), HalStatus::ok);
  }
}

TEST(Openni2Device, AnyWithoutACameraIsDisconnected) {
  std::vector<Openni2DeviceEntry> devices;
  std::string error;
  ASSERT_TRUE(list_openni2_devices(devices, error)) << error;
  for (const Openni2DeviceEntry& d : devices) {
    const bool dummy = d.uri == "Dummy" || d.uri == "Oz" || d.uri == "PingPong";  // listed once opened
    if (d.usb_vendor_id != 0 && !dummy) GTEST_SKIP() << "a camera is connected: " << d.uri;
  }
  pliant::hal::SteadyClock clock;
  Openni2Camera camera(clock, Openni2CameraConfig{});
  EXPECT_EQ(camera.configure(), HalStatus::disconnected);
  EXPECT_NE(camera.last_error().find("no OpenNI2 depth camera connected"), std::string::npos) << camera.last_error();
}

TEST(Openni2Device, UnknownUriIsDisconnected) {
  pliant::hal::SteadyClock clock;
  Openni2CameraConfig config;
  config.location = "1d27/0601@99/99";
  Openni2Camera camera(clock, config);
  EXPECT_EQ(camera.configure(), HalStatus::disconnected);
  EXPECT_NE(camera.last_error().find("1d27/0601@99/99"), std::string::npos) << camera.last_error();
}

}  // namespace
