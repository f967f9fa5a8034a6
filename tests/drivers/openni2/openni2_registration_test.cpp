// drivers/openni2 in a hal::DeviceRegistry (openni2_registration.hpp): the two schemes, the
// room.oni fixture opened by spec and played stepped to its end (what `pliant track-depth` does
// through the registry), the driver's counters in info(), a relative path resolved, and a file
// that is not an .oni refused with the driver's reason.
#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <string>
#include <variant>

#include "oni_test_support.hpp"
#include "pliant/drivers/openni2/openni2_registration.hpp"
#include "support/temp_dir.hpp"

namespace pliant::drivers {
namespace {

using hal::HalStatus;
namespace oni = test_support::oni;

const hal::DeviceInfo::Value* field(const hal::DeviceInfo& info, const std::string& name) {
  for (const hal::DeviceInfo::Field& f : info.fields()) {
    if (f.name == name) return &f.value;
  }
  return nullptr;
}

TEST(Openni2Registration, RegistersItsSchemes) {
  hal::DeviceRegistry registry;
  register_openni2_devices(registry);
  for (const char* scheme : {"openni2", "oni"}) {
    const hal::SchemeInfo* info = registry.find(hal::DeviceCategory::depth_camera, scheme);
    ASSERT_NE(info, nullptr) << scheme;
    EXPECT_EQ(info->driver, "openni2");
  }
  EXPECT_EQ(registry.schemes().size(), 2u);
}

TEST(Openni2Registration, PlaysARecordingBySpec) {
  hal::DeviceRegistry registry;
  register_openni2_devices(registry);
  hal::ManualClock clock;
  hal::DeviceSpec spec;
  spec.scheme = "oni";
  // Relative to the working directory at open: the factory resolves it before OpenNI2 starts.
  const std::filesystem::path fixture(oni::fixture_path());
  const std::filesystem::path previous = std::filesystem::current_path();
  std::filesystem::current_path(fixture.parent_path());
  spec.location = fixture.filename().string();
  spec.parameters["playback"] = "stepped";
  hal::OpenResult opened = registry.open(hal::DeviceCategory::depth_camera, spec, clock);
  std::filesystem::current_path(previous);
  ASSERT_TRUE(opened) << opened.error;
  EXPECT_EQ(opened.driver, "openni2");
  hal::DepthCamera* camera = opened.device->depth_camera();
  ASSERT_NE(camera, nullptr);
  EXPECT_EQ(opened.device->color_camera(), nullptr);
  ASSERT_EQ(opened.device->start(), HalStatus::ok);
  int frames = 0;
  for (int reads = 0; reads < 100 && !opened.device->ended(); ++reads) {
    hal::DepthFrame frame;
    const HalStatus status = camera->read(frame);
    if (status == HalStatus::no_data) continue;
    ASSERT_EQ(status, HalStatus::ok);
    EXPECT_EQ(frame.header.sequence, static_cast<std::uint64_t>(frames + 1));
    ++frames;
    ASSERT_EQ(clock.advance(1.0 / 30), HalStatus::ok);
  }
  EXPECT_TRUE(opened.device->ended());
  EXPECT_EQ(frames, 12);  // every frame of room.oni, none skipped
  const hal::DeviceInfo info = opened.device->info();
  ASSERT_NE(field(info, "received"), nullptr);
  EXPECT_EQ(std::get<std::uint64_t>(*field(info, "received")), 12u);
  EXPECT_TRUE(std::get<bool>(*field(info, "end_of_stream")));
  EXPECT_EQ(std::get<std::string>(*field(info, "intrinsics_source")), "device_fov");
}

TEST(Openni2Registration, NotAnOniFileIsRefusedWithTheReason) {
  test_support::TempDir dir("pliant_openni2_registry_");
  const std::string junk = dir / "junk.oni";
  oni::write_bytes(junk, {'N', 'I', '1', '0'});
  hal::DeviceRegistry registry;
  register_openni2_devices(registry);
  hal::ManualClock clock;
  hal::DeviceSpec spec;
  spec.scheme = "oni";
  spec.location = junk;
  const hal::OpenResult opened = registry.open(hal::DeviceCategory::depth_camera, spec, clock);
  EXPECT_FALSE(opened);
  EXPECT_EQ(opened.status, HalStatus::io_error);
  EXPECT_FALSE(opened.error.empty());
  spec.parameters["playback"] = "fast";
  EXPECT_EQ(registry.open(hal::DeviceCategory::depth_camera, spec, clock).error,
            "parameter 'playback' = 'fast': expected one of real_time, stepped");
}

}  // namespace
}  // namespace pliant::drivers
