// Depth image -> point cloud: back-projection against analytic values, depth scales, strides and
// regions, and every malformed input (sizes, intrinsics, options, empty frames, PNG files).
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "pliant/hal/camera.hpp"
#include "pliant/vision/depth_cloud.hpp"
#include "pliant/vision/depth_image.hpp"
#include "pliant/vision/depth_text.hpp"
#include "support/temp_dir.hpp"

namespace pliant::vision {
namespace {

DepthImage constant_image(int width, int height, std::uint16_t raw) {
  return DepthImage{width, height, std::vector<std::uint16_t>(static_cast<std::size_t>(width * height), raw)};
}

// Message of the DepthError `call` throws ("" when it throws none).
template <typename Call>
std::string error_of(Call call) {
  try {
    call();
  } catch (const DepthError& error) {
    return error.what();
  }
  return "";
}

TEST(DepthCloud, BackProjectsPixelsToTheirRays) {
  const PinholeIntrinsics k{500.0, 400.0, 3.5, 2.5, 8, 6};
  DepthImage image = constant_image(8, 6, 0);
  image.data[1 * 8 + 5] = 1500;  // (u 5, v 1) at 1.5 m
  image.data[5 * 8 + 0] = 250;   // (u 0, v 5) at 0.25 m
  DepthCloud cloud;
  ASSERT_EQ(depth_to_cloud(image.view(), k, DepthToCloudOptions{}, cloud), 2u);
  // X = ((u - cx) z / fx, (v - cy) z / fy, z), in row-major pixel order.
  EXPECT_NEAR(cloud.points[0].x(), (5 - 3.5) * 1.5 / 500.0, 1e-7);
  EXPECT_NEAR(cloud.points[0].y(), (1 - 2.5) * 1.5 / 400.0, 1e-7);
  EXPECT_NEAR(cloud.points[0].z(), 1.5, 1e-7);
  EXPECT_NEAR(cloud.points[1].x(), (0 - 3.5) * 0.25 / 500.0, 1e-7);
  EXPECT_NEAR(cloud.points[1].y(), (5 - 2.5) * 0.25 / 400.0, 1e-7);
  EXPECT_NEAR(cloud.points[1].z(), 0.25, 1e-7);
  EXPECT_EQ(cloud.pixel[0], 1 * 8 + 5);
  EXPECT_EQ(cloud.pixel[1], 5 * 8 + 0);
  EXPECT_EQ(cloud.image_width, 8);
  EXPECT_EQ(cloud.image_height, 6);
}

TEST(DepthCloud, EveryPointProjectsBackToItsPixel) {
  const PinholeIntrinsics k{517.3, 516.5, 318.6, 255.3, 640, 480};
  DepthImage image = constant_image(640, 480, 0);
  for (std::size_t i = 0; i < image.data.size(); ++i)
    image.data[i] = static_cast<std::uint16_t>(2000 + (i * 7919) % 20000);
  DepthCloud cloud;
  ASSERT_EQ(depth_to_cloud(image.view(), k, DepthToCloudOptions{}, cloud), 640u * 480u);
  double worst = 0;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Eigen::Vector3d p = cloud.points[i].cast<double>();
    const double u = k.fx * p.x() / p.z() + k.cx, v = k.fy * p.y() / p.z() + k.cy;
    worst = std::max({worst, std::abs(u - cloud.pixel[i] % 640), std::abs(v - cloud.pixel[i] / 640)});
    ASSERT_NEAR(p.z(), image.data[i] * 1e-3, 1e-6);
  }
  EXPECT_LT(worst, 1e-3);  // px (float points)
}

TEST(DepthCloud, DepthScaleIsMetresPerUnit) {
  const PinholeIntrinsics k{500, 500, 1.5, 1.5, 4, 4};
  const DepthImage image = constant_image(4, 4, 10000);
  DepthCloud cloud;
  DepthToCloudOptions tum;  // TUM RGB-D: 5000 units per metre
  tum.depth_scale_m = 1.0 / 5000;
  depth_to_cloud(image.view(), k, tum, cloud);
  EXPECT_NEAR(cloud.points[0].z(), 2.0, 1e-6);
  depth_to_cloud(image.view(), k, DepthToCloudOptions{}, cloud);  // millimetres
  EXPECT_NEAR(cloud.points[0].z(), 10.0, 1e-5);
  // Lateral coordinates scale with depth: the same pixel, five times farther, five times wider.
  DepthCloud near;
  depth_to_cloud(image.view(), k, tum, near);
  EXPECT_NEAR(cloud.points[0].x() / near.points[0].x(), 5.0, 1e-5);
}

TEST(DepthCloud, StrideRegionAndRange) {
  const PinholeIntrinsics k{500, 500, 319.5, 239.5, 640, 480};
  DepthImage image = constant_image(640, 480, 1000);
  DepthCloud cloud;
  DepthToCloudOptions options;
  options.stride = 2;
  EXPECT_EQ(depth_to_cloud(image.view(), k, options, cloud), 320u * 240u);
  EXPECT_EQ(cloud_capacity(640, 480, options), 320u * 240u);
  options.stride = 3;
  options.region = PixelRect{10, 20, 30, 40};
  EXPECT_EQ(depth_to_cloud(image.view(), k, options, cloud), 10u * 14u);
  EXPECT_EQ(cloud_capacity(640, 480, options), 10u * 14u);
  EXPECT_EQ(cloud.pixel.front(), 20 * 640 + 10);
  EXPECT_EQ(cloud.pixel.back(), (20 + 39) * 640 + 10 + 27);
  // Range: the near half of the region is dropped.
  for (int v = 20; v < 40; ++v) {
    for (int u = 10; u < 40; ++u) image.data[static_cast<std::size_t>(v * 640 + u)] = 300;
  }
  options.min_depth_m = 0.5;
  EXPECT_EQ(depth_to_cloud(image.view(), k, options, cloud), 10u * 7u);
  for (const auto& p : cloud.points) EXPECT_NEAR(p.z(), 1.0, 1e-6);
  options.min_depth_m = 0;
  options.max_depth_m = 0.5;
  EXPECT_EQ(depth_to_cloud(image.view(), k, options, cloud), 10u * 7u);
  // Once reserved, converting again reuses the buffers.
  const Eigen::Vector3f* before = cloud.points.data();
  depth_to_cloud(image.view(), k, options, cloud);
  EXPECT_EQ(cloud.points.data(), before);
}

TEST(DepthCloud, PaddedRowsAreRespected) {
  // A 4x3 image inside rows of 6 elements (padding 99 must never be read as depth).
  const std::vector<std::uint16_t> padded = {1000, 1000, 1000, 1000, 99,   99,   2000, 2000, 2000,
                                             2000, 99,   99,   3000, 3000, 3000, 3000, 99,   99};
  const DepthImageView view{padded.data(), 4, 3, 6};
  DepthCloud cloud;
  ASSERT_EQ(depth_to_cloud(view, PinholeIntrinsics{100, 100, 1.5, 1, 4, 3}, DepthToCloudOptions{}, cloud), 12u);
  for (std::size_t i = 0; i < 12; ++i) EXPECT_NEAR(cloud.points[i].z(), 1.0 + static_cast<double>(i / 4), 1e-6);
  // The same through a HAL depth frame (stride in bytes).
  hal::DepthFrame frame;
  frame.width = 4;
  frame.height = 3;
  frame.stride_bytes = 12;
  frame.data = padded.data();
  frame.fx = frame.fy = 100;
  frame.cx = 1.5;
  frame.cy = 1;
  ASSERT_EQ(depth_to_cloud(depth_view(frame), intrinsics_of(frame), DepthToCloudOptions{}, cloud), 12u);
  frame.stride_bytes = 7;
  EXPECT_THROW(depth_view(frame), DepthError);
  frame.stride_bytes = 6;
  EXPECT_THROW(depth_view(frame), DepthError);
  frame.stride_bytes = 12;
  frame.data = nullptr;
  EXPECT_THROW(depth_view(frame), DepthError);
  frame.fx = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(error_of([&] { intrinsics_of(frame); }).find("no intrinsics"), std::string::npos);
}

TEST(DepthCloud, MalformedInputIsAClearError) {
  const PinholeIntrinsics k{500, 500, 319.5, 239.5, 640, 480};
  const DepthImage image = constant_image(640, 480, 1000);
  DepthCloud cloud;
  const DepthToCloudOptions good;
  auto message = [&](const DepthImageView& view, const PinholeIntrinsics& intrinsics,
                     const DepthToCloudOptions& options) {
    return error_of([&] { depth_to_cloud(view, intrinsics, options, cloud); });
  };
  // Wrong size.
  const DepthImage small = constant_image(320, 240, 1000);
  EXPECT_EQ(message(small.view(), k, good), "depth image is 320x240 but the intrinsics are for 640x480");
  // All zero, or nothing in range.
  const DepthImage zero = constant_image(640, 480, 0);
  EXPECT_EQ(message(zero.view(), k, good), "depth image has no valid pixel in the region (all zero or out of range)");
  DepthToCloudOptions far = good;
  far.min_depth_m = 2.0;
  EXPECT_NE(message(image.view(), k, far).find("no valid pixel"), std::string::npos);
  // Missing or bad intrinsics.
  EXPECT_EQ(message(image.view(), PinholeIntrinsics{}, good),
            "intrinsics: fx must be finite and > 0 (missing intrinsics?)");
  PinholeIntrinsics bad = k;
  bad.fy = -1;
  EXPECT_NE(message(image.view(), bad, good).find("fy"), std::string::npos);
  bad = k;
  bad.cx = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(message(image.view(), bad, good).find("cx"), std::string::npos);
  bad = k;
  bad.fx = std::numeric_limits<double>::infinity();
  EXPECT_NE(message(image.view(), bad, good).find("fx"), std::string::npos);
  // Bad views.
  EXPECT_EQ(message(DepthImageView{}, k, good), "depth image: no data");
  EXPECT_NE(message(DepthImageView{image.data.data(), 640, 480, 100}, k, good).find("row_stride"), std::string::npos);
  EXPECT_NE(message(DepthImageView{image.data.data(), 0, 480, 0}, k, good).find("empty"), std::string::npos);
  // Bad options.
  auto option_error = [&](auto change) {
    DepthToCloudOptions options = good;
    change(options);
    return message(image.view(), k, options);
  };
  EXPECT_NE(option_error([](auto& o) { o.depth_scale_m = 0; }).find("depth_scale_m"), std::string::npos);
  EXPECT_NE(option_error([](auto& o) { o.depth_scale_m = std::nan(""); }).find("depth_scale_m"), std::string::npos);
  EXPECT_NE(option_error([](auto& o) { o.stride = 0; }).find("stride"), std::string::npos);
  EXPECT_NE(option_error([](auto& o) { o.min_depth_m = -1; }).find("min_depth_m"), std::string::npos);
  EXPECT_NE(option_error([](auto& o) { o.max_depth_m = 0; }).find("max_depth_m"), std::string::npos);
  EXPECT_NE(option_error([](auto& o) { o.region = PixelRect{600, 0, 50, 10}; }).find("not inside"), std::string::npos);
  EXPECT_NE(option_error([](auto& o) { o.region = PixelRect{-1, 0, 50, 10}; }).find("not inside"), std::string::npos);
  EXPECT_NE(option_error([](auto& o) { o.region = PixelRect{0, 0, 10, -5}; }).find("not inside"), std::string::npos);
  // The unchecked conversion of an empty frame is an empty cloud, not an error.
  EXPECT_EQ(depth_to_cloud_unchecked(zero.view(), k, good, cloud), 0u);
  EXPECT_EQ(cloud.size(), 0u);
}

TEST(DepthCloud, IntrinsicsFromText) {
  const PinholeIntrinsics k = parse_intrinsics("517.3,516.5,318.6,255.3", 640, 480);
  EXPECT_EQ(k.fx, 517.3);
  EXPECT_EQ(k.fy, 516.5);
  EXPECT_EQ(k.cx, 318.6);
  EXPECT_EQ(k.cy, 255.3);
  EXPECT_EQ(k.width, 640);
  EXPECT_EQ(parse_intrinsics(" 525 , 525,319.5 ,239.5", 640, 480).cy, 239.5);
  auto message = [](const char* text) { return error_of([&] { parse_intrinsics(text, 640, 480); }); };
  EXPECT_EQ(message("517.3,516.5,318.6"), "intrinsics: cy is missing (expected fx,fy,cx,cy)");
  EXPECT_EQ(message(""), "intrinsics: fx is missing (expected fx,fy,cx,cy)");
  EXPECT_EQ(message("a,1,2,3"), "intrinsics: fx is not a number: 'a'");
  EXPECT_EQ(message("1,2,3,4,5"), "intrinsics: trailing text after cy (expected fx,fy,cx,cy)");
  EXPECT_EQ(message("1,2,3,4x"), "intrinsics: cy is not a number: '4x'");
  EXPECT_EQ(message("0,1,2,3"), "intrinsics: fx must be finite and > 0 (missing intrinsics?)");
  EXPECT_EQ(message("1,2,3,\n4"), "intrinsics: cy is not a number: '\\x0a4'");  // one line, always
  EXPECT_NE(message("1e999,1,2,3").find("not a number"), std::string::npos);
  EXPECT_NE(message("nan,1,2,3").find("fx"), std::string::npos);
  EXPECT_NE(error_of([] { parse_intrinsics("1,1,1,1", 0, 480); }).find("width"), std::string::npos);
}

TEST(DepthCloud, CameraPoseAndRegionFromText) {
  const Eigen::Isometry3d pose = parse_camera_pose("0.1, 0.2,0.3,0,0,0,1");
  EXPECT_TRUE(pose.linear().isIdentity(1e-12));
  EXPECT_TRUE(pose.translation().isApprox(Eigen::Vector3d(0.1, 0.2, 0.3)));
  const double h = std::sqrt(0.5);
  const Eigen::Isometry3d turned = parse_camera_pose("0,0,0,0,0," + std::to_string(h) + "," + std::to_string(h));
  EXPECT_TRUE((turned.linear() * Eigen::Vector3d::UnitX()).isApprox(Eigen::Vector3d::UnitY(), 1e-6));  // 90 deg about z
  auto pose_error = [](const std::string& text) { return error_of([&] { parse_camera_pose(text); }); };
  EXPECT_EQ(pose_error("0,0,0,0,0,0"), "camera pose: qw is missing (expected tx,ty,tz,qx,qy,qz,qw)");
  EXPECT_EQ(pose_error("0,0,0,0,0,0,2"), "camera pose: the quaternion must have norm 1");
  EXPECT_EQ(pose_error("0,0,0,0,0,0,0"), "camera pose: the quaternion must have norm 1");
  EXPECT_EQ(pose_error("nan,0,0,0,0,0,1"), "camera pose: every field must be finite");
  EXPECT_EQ(pose_error("0,0,0,0,0,0,1,"), "camera pose: trailing text after qw (expected tx,ty,tz,qx,qy,qz,qw)");

  const PixelRect r = parse_pixel_rect("10,20,30,40");
  EXPECT_EQ(r.u0, 10);
  EXPECT_EQ(r.v0, 20);
  EXPECT_EQ(r.width, 30);
  EXPECT_EQ(r.height, 40);
  auto region_error = [](const std::string& text) { return error_of([&] { parse_pixel_rect(text); }); };
  EXPECT_EQ(region_error("1.5,0,1,1"), "region: u0 must be a whole number >= 0");
  EXPECT_EQ(region_error("0,-1,1,1"), "region: v0 must be a whole number >= 0");
  EXPECT_EQ(region_error("0,0,0,5"), "region: width and height must be >= 1");
  EXPECT_EQ(region_error("0,0,1e12,5"), "region: width must be a whole number >= 0");
  EXPECT_EQ(region_error("0,0,5"), "region: height is missing (expected u0,v0,width,height)");
  EXPECT_EQ(region_error(std::string(60, '7') + ",0,1,1"),
            "region: u0 is not a number: '" + std::string(40, '7') + "...'");
}

TEST(DepthPng, ReadsSixteenBitAndRefusesTheRest) {
  test_support::TempDir dir("pliant_depth_png_");
  // A 16-bit single-channel PNG round trip.
  cv::Mat depth(3, 5, CV_16UC1);
  for (int v = 0; v < 3; ++v) {
    for (int u = 0; u < 5; ++u)
      depth.at<std::uint16_t>(v, u) = static_cast<std::uint16_t>(1000 * v + u + 60000 * (u == 4));
  }
  ASSERT_TRUE(cv::imwrite(dir / "depth.png", depth));
  const DepthImage image = read_depth_png(dir / "depth.png");
  ASSERT_EQ(image.width, 5);
  ASSERT_EQ(image.height, 3);
  EXPECT_EQ(image.view().at(2, 1), 1002);
  EXPECT_EQ(image.view().at(4, 2), 62004);
  // Refused, each with the file named.
  auto message = [](const std::string& path) { return error_of([&] { read_depth_png(path); }); };
  EXPECT_EQ(message(dir / "missing.png"), dir / "missing.png" + ": cannot open");
  const cv::Mat eight(4, 4, CV_8UC1, cv::Scalar(7));
  ASSERT_TRUE(cv::imwrite(dir / "eight.png", eight));
  EXPECT_EQ(message(dir / "eight.png"), dir / "eight.png" + ": depth PNG must be 16-bit (this one is 8-bit)");
  const cv::Mat three(4, 4, CV_16UC3, cv::Scalar(7, 8, 9));
  ASSERT_TRUE(cv::imwrite(dir / "three.png", three));
  EXPECT_NE(message(dir / "three.png").find("one channel (this one has 3)"), std::string::npos);
  std::ofstream(dir / "empty.png").close();
  EXPECT_EQ(message(dir / "empty.png"), dir / "empty.png" + ": empty file");
  std::ofstream(dir / "text.png") << "this is not an image";
  EXPECT_EQ(message(dir / "text.png"), dir / "text.png" + ": not a PNG file");
  // The TUM frame cut short, and with its image data scrambled: corrupt, and nothing printed.
  std::ifstream whole(std::string(PLIANT_TEST_DATA_DIR) + "/rgbd_tum/TUM_depth.png", std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(whole)), std::istreambuf_iterator<char>());
  ASSERT_GT(bytes.size(), 10000u);
  std::ofstream(dir / "cut.png", std::ios::binary) << bytes.substr(0, 5000);
  std::ofstream(dir / "header.png", std::ios::binary) << bytes.substr(0, 20);
  for (std::size_t i = 2000; i < 2100; ++i) bytes[i] = static_cast<char>(bytes[i] ^ 0x5a);
  std::ofstream(dir / "scrambled.png", std::ios::binary) << bytes;
  testing::internal::CaptureStderr();
  const std::string cut = message(dir / "cut.png");
  const std::string header = message(dir / "header.png");
  const std::string scrambled = message(dir / "scrambled.png");
  EXPECT_EQ(testing::internal::GetCapturedStderr(), "");
  EXPECT_EQ(cut, dir / "cut.png" + ": corrupt PNG (file cut short)");
  EXPECT_EQ(header, dir / "header.png" + ": corrupt PNG (file cut short)");
  EXPECT_NE(scrambled.find(": corrupt PNG ("), std::string::npos) << scrambled;
  // Too large: a 20000 x 1 image is refused before any buffer is allocated.
  cv::imwrite(dir / "wide.png", cv::Mat(1, 20000, CV_16UC1, cv::Scalar(1)));
  EXPECT_EQ(message(dir / "wide.png"), dir / "wide.png" + ": image of 20000x1 pixels is larger than 16384 on a side");
  // A header claiming 16000 x 16000 pixels over a few bytes of data.
  std::string claim = std::string(bytes.substr(0, 33));
  claim[16] = claim[20] = 0;
  claim[17] = claim[21] = 0;
  claim[18] = claim[22] = static_cast<char>(16000 >> 8);
  claim[19] = claim[23] = static_cast<char>(16000 & 0xff);
  std::uint32_t crc = 0xffffffffu;  // PNG's CRC-32 over the chunk type and data
  for (std::size_t i = 12; i < 29; ++i) {
    crc ^= static_cast<std::uint8_t>(claim[i]);
    for (int bit = 0; bit < 8; ++bit) crc = (crc >> 1) ^ (0xedb88320u & (0u - (crc & 1u)));
  }
  crc ^= 0xffffffffu;
  for (int b = 0; b < 4; ++b) claim[static_cast<std::size_t>(29 + b)] = static_cast<char>((crc >> (24 - 8 * b)) & 0xff);
  claim += std::string("\0\0\0\x64IDAT", 8) + std::string(100, '\0');
  EXPECT_EQ(error_of([&] {
              decode_depth_png(reinterpret_cast<const std::uint8_t*>(claim.data()), claim.size(), "claim.png");
            }),
            "claim.png: corrupt PNG (141 bytes cannot hold a 16000x16000 image)");
  EXPECT_THROW(decode_depth_png(nullptr, 0, "x"), DepthError);
}

}  // namespace
}  // namespace pliant::vision
