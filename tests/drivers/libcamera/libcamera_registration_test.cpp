// drivers/libcamera in a hal::DeviceRegistry (libcamera_registration.hpp): the scheme and its
// parameter checks (refused before libcamera is touched). Opening a real camera is the live
// test's business (it skips without one).
#include <gtest/gtest.h>

#include <string>

#include "pliant/drivers/libcamera/libcamera_registration.hpp"

namespace pliant::drivers {
namespace {

TEST(LibcameraRegistration, RegistersItsSchemeAndChecksParameters) {
  hal::DeviceRegistry registry;
  register_libcamera_devices(registry);
  const hal::SchemeInfo* info = registry.find(hal::DeviceCategory::color_camera, "libcamera");
  ASSERT_NE(info, nullptr);
  EXPECT_EQ(info->driver, "libcamera");
  EXPECT_EQ(info->parameters, std::vector<std::string>{"format"});

  hal::ManualClock clock;
  hal::DeviceSpec spec;
  spec.scheme = "libcamera";
  spec.location = "any";
  spec.parameters["format"] = "nv12";
  const hal::OpenResult bad = registry.open(hal::DeviceCategory::color_camera, spec, clock);
  EXPECT_EQ(bad.status, hal::HalStatus::invalid_argument);
  EXPECT_EQ(bad.error, "parameter 'format' = 'nv12': expected one of rgb8, bgr8, mono8");
  spec.parameters.clear();
  spec.parameters["fps"] = "30";
  EXPECT_EQ(registry.open(hal::DeviceCategory::color_camera, spec, clock).error,
            "libcamera has no parameter 'fps' (it takes format)");
}

}  // namespace
}  // namespace pliant::drivers
