// libcamera itself: starts the CameraManager and, when it lists a camera, captures a few frames;
// without a camera (containers, CI) the capture test is skipped and configure must say so.
#include <gtest/gtest.h>

#include <chrono>
#include <string>
#include <thread>
#include <vector>

#include "pliant/drivers/libcamera/libcamera_camera.hpp"

namespace pliant::drivers {
namespace {

using hal::HalStatus;

TEST(LibcameraLive, ConfigureWithoutACameraIsAClearError) {
  std::string error;
  const std::vector<std::string> cameras = list_libcamera_cameras(&error);
  if (!cameras.empty())
    GTEST_SKIP() << "libcamera lists " << cameras.size() << " camera(s): the no-camera path is not reachable";
  hal::ManualClock clock;
  LibcameraCamera camera(clock, LibcameraCameraConfig{});
  EXPECT_EQ(camera.configure(), HalStatus::disconnected);
  EXPECT_NE(camera.last_error().find("no camera"), std::string::npos) << camera.last_error();
  EXPECT_EQ(camera.state(), hal::LifecycleState::unconfigured);
}

TEST(LibcameraLive, CapturesFromTheFirstCamera) {
  std::string error;
  const std::vector<std::string> cameras = list_libcamera_cameras(&error);
  if (cameras.empty()) GTEST_SKIP() << "no camera (libcamera lists none" << (error.empty() ? "" : ": " + error) << ")";
  hal::SteadyClock clock;
  LibcameraCameraConfig config;
  config.camera_id = cameras.front();
  LibcameraCamera camera(clock, config);
  const HalStatus configured = camera.configure();
  if (configured == HalStatus::unsupported) GTEST_SKIP() << camera.last_error();
  ASSERT_EQ(configured, HalStatus::ok) << camera.last_error();
  ASSERT_EQ(camera.start(), HalStatus::ok);
  hal::ColorFrame frame;
  int frames = 0;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (frames < 3 && std::chrono::steady_clock::now() < deadline) {
    const HalStatus status = camera.read(frame);
    ASSERT_TRUE(status == HalStatus::ok || status == HalStatus::no_data) << hal::hal_status_name(status);
    if (status == HalStatus::ok) {
      ++frames;
      EXPECT_EQ(frame.width, camera.width());
      EXPECT_LE(frame.header.stamp_s, clock.now_s());
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  EXPECT_EQ(frames, 3) << camera.stream_description();
  EXPECT_EQ(camera.stop(), HalStatus::ok);
  EXPECT_EQ(camera.cleanup(), HalStatus::ok);
}

}  // namespace
}  // namespace pliant::drivers
