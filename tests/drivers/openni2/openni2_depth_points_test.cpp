// drivers/openni2 depth_points: intrinsics from a field of view, back-projection, frame copy;
// and an oracle check against OpenNI2's own CoordinateConverter on the recording.
#include <OpenNI.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

#include "oni_test_support.hpp"
#include "pliant/drivers/openni2/depth_points.hpp"
#include "pliant/drivers/openni2/openni2_camera.hpp"
#include "pliant/hal/clock.hpp"

namespace {

using namespace pliant::drivers::openni2;
constexpr double kPi = 3.14159265358979323846;
const double kNaN = std::numeric_limits<double>::quiet_NaN();

TEST(Openni2Intrinsics, FromKinectFieldOfView) {
  // 58 x 45 degrees on 640 x 480: fx = 320 / tan(29 deg), fy = 240 / tan(22.5 deg).
  DepthIntrinsics k;
  ASSERT_EQ(intrinsics_from_fov(58 * kPi / 180, 45 * kPi / 180, 640, 480, k), IntrinsicsCheck::ok);
  EXPECT_NEAR(k.fx, 577.2953, 1e-3);
  EXPECT_NEAR(k.fy, 579.4113, 1e-3);
  EXPECT_DOUBLE_EQ(k.cx, 319.5);
  EXPECT_DOUBLE_EQ(k.cy, 239.5);
  EXPECT_EQ(k.width, 640);
  EXPECT_EQ(k.height, 480);
  // 90 degrees: the focal length is half the width.
  ASSERT_EQ(intrinsics_from_fov(kPi / 2, kPi / 2, 100, 100, k), IntrinsicsCheck::ok);
  EXPECT_NEAR(k.fx, 50, 1e-12);
  EXPECT_NEAR(k.fy, 50, 1e-12);
}

TEST(Openni2Intrinsics, RefusesUnusableFieldOfView) {
  DepthIntrinsics k;
  k.fx = 123;
  const double bad[] = {0, -0.5, kNaN, std::numeric_limits<double>::infinity(), kPi, 4.0, 0.01};
  for (double angle : bad) {
    EXPECT_EQ(intrinsics_from_fov(angle, 0.8, 640, 480, k), IntrinsicsCheck::bad_fov) << angle;
    EXPECT_EQ(intrinsics_from_fov(1.0, angle, 640, 480, k), IntrinsicsCheck::bad_fov) << angle;
    EXPECT_FALSE(fov_is_valid(angle, 0.8));
  }
  EXPECT_EQ(k.fx, 123) << "out must stay untouched on failure";
  EXPECT_EQ(intrinsics_from_fov(1.0, 0.8, 0, 480, k), IntrinsicsCheck::bad_size);
  EXPECT_EQ(intrinsics_from_fov(1.0, 0.8, 640, kMaxDepthSide + 1, k), IntrinsicsCheck::bad_size);
  // 100 x 10 degrees on a square image: pixels 8x taller than wide.
  EXPECT_EQ(intrinsics_from_fov(100 * kPi / 180, 10 * kPi / 180, 100, 100, k), IntrinsicsCheck::aspect_mismatch);
  EXPECT_TRUE(fov_is_valid(1.0144686, 0.7898090));
}

TEST(Openni2Intrinsics, ChecksConfiguredIntrinsics) {
  DepthIntrinsics k{300, 300, 159.5, 119.5, 320, 240};
  EXPECT_EQ(check_intrinsics(k), IntrinsicsCheck::ok);
  DepthIntrinsics bad = k;
  bad.fx = 0;
  EXPECT_EQ(check_intrinsics(bad), IntrinsicsCheck::bad_focal);
  bad = k;
  bad.fy = kNaN;
  EXPECT_EQ(check_intrinsics(bad), IntrinsicsCheck::bad_focal);
  bad = k;
  bad.fx = 1e-4;
  EXPECT_EQ(check_intrinsics(bad), IntrinsicsCheck::bad_focal);
  bad = k;
  bad.fy = 2e9;
  EXPECT_EQ(check_intrinsics(bad), IntrinsicsCheck::bad_focal);
  bad = k;
  bad.cx = 700;
  EXPECT_EQ(check_intrinsics(bad), IntrinsicsCheck::bad_principal);
  bad = k;
  bad.cy = std::numeric_limits<double>::infinity();
  EXPECT_EQ(check_intrinsics(bad), IntrinsicsCheck::bad_principal);
  bad = k;
  bad.width = 0;
  EXPECT_EQ(check_intrinsics(bad), IntrinsicsCheck::bad_size);
  EXPECT_EQ(check_intrinsics(DepthIntrinsics{}), IntrinsicsCheck::bad_size);
  EXPECT_STREQ(intrinsics_check_name(IntrinsicsCheck::bad_principal), "bad_principal");
}

// A 3 x 2 image with 2 bytes of padding per row (stride 8).
std::vector<std::uint8_t> small_image() {
  const std::uint16_t rows[2][4] = {{1000, 0, 2000, 0xBEEF}, {500, 1500, 0, 0xBEEF}};
  std::vector<std::uint8_t> bytes(16);
  std::memcpy(bytes.data(), rows, 16);
  return bytes;
}

TEST(Openni2DepthToPoints, BackProjectsEachPixel) {
  const std::vector<std::uint8_t> image = small_image();
  const DepthIntrinsics k{100, 200, 1, 0.5, 3, 2};
  std::vector<double> xyz(18, -1);
  const PointsResult r = depth_to_points(image.data(), image.size(), 3, 2, 8, 1e-3, k, xyz.data(), 6);
  ASSERT_EQ(r.status, PointsStatus::ok);
  EXPECT_EQ(r.valid_points, 4u);
  // (u, v) = (0, 0), z = 1 m: x = (0 - 1) / 100, y = (0 - 0.5) / 200.
  EXPECT_DOUBLE_EQ(xyz[0], -0.01);
  EXPECT_DOUBLE_EQ(xyz[1], -0.0025);
  EXPECT_DOUBLE_EQ(xyz[2], 1.0);
  EXPECT_TRUE(std::isnan(xyz[3]) && std::isnan(xyz[4]) && std::isnan(xyz[5]));
  // (2, 0), z = 2 m: x = 1 * 2 / 100.
  EXPECT_DOUBLE_EQ(xyz[6], 0.02);
  EXPECT_DOUBLE_EQ(xyz[7], -0.005);
  EXPECT_DOUBLE_EQ(xyz[8], 2.0);
  // (0, 1), z = 0.5 m; (1, 1), z = 1.5 m: x = 0, y = 0.5 * 1.5 / 200.
  EXPECT_DOUBLE_EQ(xyz[9], -0.005);
  EXPECT_DOUBLE_EQ(xyz[10], 0.00125);
  EXPECT_DOUBLE_EQ(xyz[12], 0.0);
  EXPECT_DOUBLE_EQ(xyz[13], 0.00375);
  EXPECT_DOUBLE_EQ(xyz[14], 1.5);
  EXPECT_TRUE(std::isnan(xyz[15]));

  std::vector<float> xyz_f(18, -1);
  ASSERT_EQ(depth_to_points(image.data(), image.size(), 3, 2, 8, 1e-3, k, xyz_f.data(), 6).status, PointsStatus::ok);
  for (std::size_t i = 0; i < 18; ++i) {
    if (std::isnan(xyz[i])) {
      EXPECT_TRUE(std::isnan(xyz_f[i]));
    } else {
      EXPECT_NEAR(xyz_f[i], xyz[i], 1e-6);
    }
  }
}

TEST(Openni2DepthToPoints, ReadsUnalignedRows) {
  const std::vector<std::uint8_t> image = small_image();
  std::vector<std::uint8_t> shifted(image.size() + 1);
  std::memcpy(shifted.data() + 1, image.data(), image.size());
  const DepthIntrinsics k{100, 200, 1, 0.5, 3, 2};
  std::vector<double> a(18), b(18);
  ASSERT_EQ(depth_to_points(image.data(), image.size(), 3, 2, 8, 1e-3, k, a.data(), 6).status, PointsStatus::ok);
  ASSERT_EQ(depth_to_points(shifted.data() + 1, image.size(), 3, 2, 8, 1e-3, k, b.data(), 6).status, PointsStatus::ok);
  for (std::size_t i = 0; i < 18; ++i) EXPECT_TRUE((std::isnan(a[i]) && std::isnan(b[i])) || a[i] == b[i]);
}

TEST(Openni2DepthToPoints, RefusesBadLayoutsWithoutWriting) {
  const std::vector<std::uint8_t> image = small_image();
  const DepthIntrinsics k{100, 200, 1, 0.5, 3, 2};
  std::vector<double> xyz(18, 7);
  const auto status = [&](const std::uint8_t* data, std::size_t bytes, int w, int h, std::size_t stride, double scale,
                          const DepthIntrinsics& kk, std::size_t capacity) {
    return depth_to_points(data, bytes, w, h, stride, scale, kk, xyz.data(), capacity).status;
  };
  EXPECT_EQ(status(image.data(), 16, 0, 2, 8, 1e-3, k, 6), PointsStatus::bad_size);
  EXPECT_EQ(status(image.data(), 16, 3, -1, 8, 1e-3, k, 6), PointsStatus::bad_size);
  EXPECT_EQ(status(image.data(), 16, 3, 2, 5, 1e-3, k, 6), PointsStatus::bad_stride);
  EXPECT_EQ(status(image.data(), 13, 3, 2, 8, 1e-3, k, 6), PointsStatus::buffer_too_small);
  EXPECT_EQ(status(image.data(), 16, 3, 2, std::numeric_limits<std::size_t>::max() / 2, 1e-3, k, 6),
            PointsStatus::buffer_too_small);
  EXPECT_EQ(status(nullptr, 16, 3, 2, 8, 1e-3, k, 6), PointsStatus::buffer_too_small);
  EXPECT_EQ(status(image.data(), 16, 3, 2, 8, 0, k, 6), PointsStatus::bad_scale);
  EXPECT_EQ(status(image.data(), 16, 3, 2, 8, kNaN, k, 6), PointsStatus::bad_scale);
  EXPECT_EQ(status(image.data(), 16, 3, 2, 8, 2, k, 6), PointsStatus::bad_scale);
  DepthIntrinsics other = k;
  other.width = 4;
  EXPECT_EQ(status(image.data(), 16, 3, 2, 8, 1e-3, other, 6), PointsStatus::bad_intrinsics);
  EXPECT_EQ(status(image.data(), 16, 3, 2, 8, 1e-3, DepthIntrinsics{}, 6), PointsStatus::bad_intrinsics);
  EXPECT_EQ(status(image.data(), 16, 3, 2, 8, 1e-3, k, 5), PointsStatus::output_too_small);
  for (double v : xyz) EXPECT_EQ(v, 7);
  // The last row needs only 2 * width bytes, not a whole stride.
  EXPECT_EQ(status(image.data(), 14, 3, 2, 8, 1e-3, k, 6), PointsStatus::ok);
  EXPECT_STREQ(points_status_name(PointsStatus::output_too_small), "output_too_small");
}

TEST(Openni2DepthToPoints, HalFrameCarriesItsIntrinsics) {
  const std::uint16_t pixels[4] = {1000, 0, 0, 2000};
  pliant::hal::DepthFrame frame;
  frame.width = 2;
  frame.height = 2;
  frame.stride_bytes = 4;
  frame.data = pixels;
  std::vector<double> xyz(12);
  EXPECT_EQ(depth_to_points(frame, xyz.data(), 4).status, PointsStatus::bad_intrinsics) << "NaN intrinsics";
  frame.fx = frame.fy = 1;
  frame.cx = frame.cy = 0.5;
  const PointsResult r = depth_to_points(frame, xyz.data(), 4);
  ASSERT_EQ(r.status, PointsStatus::ok);
  EXPECT_EQ(r.valid_points, 2u);
  EXPECT_DOUBLE_EQ(xyz[0], -0.5);
  EXPECT_DOUBLE_EQ(xyz[9], 1.0);
  EXPECT_DOUBLE_EQ(xyz[11], 2.0);
  frame.stride_bytes = -4;
  EXPECT_EQ(depth_to_points(frame, xyz.data(), 4).status, PointsStatus::bad_size);
}

TEST(Openni2DepthToPoints, CopyDepthImagePacksRows) {
  const std::vector<std::uint8_t> image = small_image();
  std::vector<std::uint16_t> packed(6, 9);
  ASSERT_TRUE(copy_depth_image(image.data(), image.size(), 3, 2, 8, packed.data(), packed.size()));
  EXPECT_EQ(packed, (std::vector<std::uint16_t>{1000, 0, 2000, 500, 1500, 0}));
  std::vector<std::uint16_t> small(5, 9);
  EXPECT_FALSE(copy_depth_image(image.data(), image.size(), 3, 2, 8, small.data(), small.size()));
  EXPECT_FALSE(copy_depth_image(image.data(), 12, 3, 2, 8, packed.data(), packed.size()));
  EXPECT_FALSE(copy_depth_image(image.data(), image.size(), 3, 2, 4, packed.data(), packed.size()));
  EXPECT_FALSE(copy_depth_image(nullptr, image.size(), 3, 2, 8, packed.data(), packed.size()));
  EXPECT_EQ(small, std::vector<std::uint16_t>(5, 9));
}

// Oracle: OpenNI2's CoordinateConverter on the recording's stream gives the same points once
// its conventions are applied (centre at width / 2: ask it for pixel + 0.5; y up: negate; mm).
TEST(Openni2DepthToPoints, AgreesWithOpenNi2CoordinateConverter) {
  pliant::hal::ManualClock clock;
  Openni2CameraConfig config;
  config.source = Openni2Source::recording;
  config.location = pliant::test_support::oni::fixture_path();
  config.playback = Openni2Playback::stepped;
  Openni2Camera camera(clock, config);
  ASSERT_EQ(camera.configure(), pliant::hal::HalStatus::ok) << camera.last_error();
  ASSERT_EQ(camera.stats().intrinsics_source, IntrinsicsSource::device_fov);
  const DepthIntrinsics k = camera.intrinsics();

  ASSERT_EQ(openni::OpenNI::initialize(), openni::STATUS_OK);  // counted: the driver initialised already
  openni::Device device;
  ASSERT_EQ(device.open(config.location.c_str()), openni::STATUS_OK) << openni::OpenNI::getExtendedError();
  openni::VideoStream stream;
  ASSERT_EQ(stream.create(device, openni::SENSOR_DEPTH), openni::STATUS_OK);
  const int us[] = {0, 100, 319, 320, 639};
  const int vs[] = {0, 240, 479};
  std::vector<std::uint16_t> image(640 * 480, 0);
  std::vector<double> ours(640 * 480 * 3);
  for (double z_mm : {500.0, 1234.0, 4000.0}) {
    for (int u : us) {
      for (int v : vs)
        image[static_cast<std::size_t>(v) * 640 + static_cast<std::size_t>(u)] = static_cast<std::uint16_t>(z_mm);
    }
    const PointsResult r = depth_to_points(reinterpret_cast<const std::uint8_t*>(image.data()), image.size() * 2, 640,
                                           480, 1280, 1e-3, k, ours.data(), 640 * 480);
    ASSERT_EQ(r.status, PointsStatus::ok);
    ASSERT_EQ(r.valid_points, 15u);
    for (int u : us) {
      for (int v : vs) {
        const double* p = &ours[3 * (static_cast<std::size_t>(v) * 640 + static_cast<std::size_t>(u))];
        float wx = 0, wy = 0, wz = 0;
        ASSERT_EQ(openni::CoordinateConverter::convertDepthToWorld(stream, static_cast<float>(u) + 0.5f,
                                                                   static_cast<float>(v) + 0.5f,
                                                                   static_cast<float>(z_mm), &wx, &wy, &wz),
                  openni::STATUS_OK);
        // OpenNI2 computes in single precision: agree to 1e-5 of the depth.
        EXPECT_NEAR(p[0], 1e-3 * static_cast<double>(wx), 1e-5 * z_mm * 1e-3) << u << "," << v;
        EXPECT_NEAR(p[1], -1e-3 * static_cast<double>(wy), 1e-5 * z_mm * 1e-3) << u << "," << v;
        EXPECT_NEAR(p[2], 1e-3 * static_cast<double>(wz), 1e-9);
      }
    }
  }
  stream.destroy();
  device.close();
  EXPECT_EQ(camera.cleanup(), pliant::hal::HalStatus::ok);
}

}  // namespace
