// drivers/opencv in a hal::DeviceRegistry (opencv_registration.hpp): the three schemes, a video
// opened by spec (format and playback parameters, end of stream, the driver's counters in
// info()), and the errors of a missing file and of bad parameters.
#include <gtest/gtest.h>

#include <string>
#include <variant>

#include "opencv_test_media.hpp"
#include "pliant/drivers/opencv/opencv_registration.hpp"
#include "support/temp_dir.hpp"

namespace pliant::drivers {
namespace {

using hal::HalStatus;

const hal::DeviceInfo::Value* field(const hal::DeviceInfo& info, const std::string& name) {
  for (const hal::DeviceInfo::Field& f : info.fields()) {
    if (f.name == name) return &f.value;
  }
  return nullptr;
}

TEST(OpenCvRegistration, RegistersItsSchemes) {
  hal::DeviceRegistry registry;
  register_opencv_devices(registry);
  for (const char* scheme : {"v4l2", "video", "images"}) {
    const hal::SchemeInfo* info = registry.find(hal::DeviceCategory::color_camera, scheme);
    ASSERT_NE(info, nullptr) << scheme;
    EXPECT_EQ(info->driver, "opencv");
  }
  EXPECT_EQ(registry.schemes().size(), 3u);
}

TEST(OpenCvRegistration, OpensAVideoBySpec) {
  test_support::TempDir dir("pliant_opencv_registry_");
  const std::string video = (dir.path() / "clip.avi").string();
  opencv_test::write_video(video, 4, 10.0);
  hal::DeviceRegistry registry;
  register_opencv_devices(registry);
  hal::ManualClock clock(5.0);

  hal::DeviceSpec spec;
  spec.scheme = "video";
  spec.location = video;
  spec.parameters["playback"] = "stepped";
  spec.parameters["format"] = "mono8";
  hal::OpenResult opened = registry.open(hal::DeviceCategory::color_camera, spec, clock);
  ASSERT_TRUE(opened) << opened.error;
  EXPECT_EQ(opened.driver, "opencv");
  hal::ColorCamera* camera = opened.device->color_camera();
  ASSERT_NE(camera, nullptr);
  ASSERT_EQ(opened.device->start(), HalStatus::ok);
  hal::ColorFrame frame;
  for (int k = 0; k < 4; ++k) {
    ASSERT_EQ(camera->read(frame), HalStatus::ok) << k;
    EXPECT_EQ(frame.format, hal::PixelFormat::mono8);
    EXPECT_EQ(frame.width, 64);
    EXPECT_FALSE(opened.device->ended());
  }
  EXPECT_EQ(camera->read(frame), HalStatus::no_data);
  EXPECT_TRUE(opened.device->ended());
  const hal::DeviceInfo info = opened.device->info();
  ASSERT_NE(field(info, "source"), nullptr);
  EXPECT_EQ(std::get<std::string>(*field(info, "source")), "video_file");
  EXPECT_EQ(std::get<std::int64_t>(*field(info, "width")), 64);
  EXPECT_EQ(std::get<std::uint64_t>(*field(info, "decoded")), 4u);
  EXPECT_TRUE(std::get<bool>(*field(info, "end_of_stream")));

  spec.parameters.erase("format");  // bgr8 unless asked
  hal::OpenResult bgr = registry.open(hal::DeviceCategory::color_camera, spec, clock);
  ASSERT_TRUE(bgr) << bgr.error;
  ASSERT_EQ(bgr.device->start(), HalStatus::ok);
  ASSERT_EQ(bgr.device->color_camera()->read(frame), HalStatus::ok);
  EXPECT_EQ(frame.format, hal::PixelFormat::bgr8);
}

TEST(OpenCvRegistration, MissingFilesAndBadParameters) {
  test_support::TempDir dir("pliant_opencv_registry_");
  hal::DeviceRegistry registry;
  register_opencv_devices(registry);
  hal::ManualClock clock;
  hal::DeviceSpec spec;
  spec.scheme = "video";
  spec.location = (dir.path() / "missing.avi").string();
  const hal::OpenResult missing = registry.open(hal::DeviceCategory::color_camera, spec, clock);
  EXPECT_FALSE(missing);
  EXPECT_EQ(missing.status, HalStatus::io_error);
  EXPECT_FALSE(missing.error.empty());

  spec.parameters["format"] = "yuv";
  EXPECT_EQ(registry.open(hal::DeviceCategory::color_camera, spec, clock).error,
            "parameter 'format' = 'yuv': expected one of rgb8, bgr8, mono8");
  hal::DeviceSpec webcam;
  webcam.scheme = "v4l2";
  webcam.location = "/dev/video99";
  webcam.parameters["playback"] = "stepped";
  const hal::OpenResult stepped = registry.open(hal::DeviceCategory::color_camera, webcam, clock);
  EXPECT_EQ(stepped.status, HalStatus::invalid_argument);
  EXPECT_EQ(stepped.error, "v4l2 has no parameter 'playback' (it takes format)");
}

}  // namespace
}  // namespace pliant::drivers
