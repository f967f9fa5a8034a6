// A real depth frame: TUM RGB-D fr1 (Kinect v1, 640 x 480, 16-bit PNG at 5000 units per metre;
// tests/data/rgbd_tum/PROVENANCE.md). The scene is an office: a floor in the lower part of the
// image, desks, and a partition wall behind them about 2.7 m away.
//
// What is checked, with the documented intrinsics (fx 517.3, fy 516.5, cx 318.6, cy 255.3) and
// depth scale 1/5000 m:
//  1. the frame decodes to 640 x 480 and about four fifths of its pixels carry depth;
//  2. the floor (pixels u 250..399, v 435..469, between the chairs): a RANSAC plane (2 cm
//     inlier band) holds at least 95 % of the points; refitted by least squares (PCA) to its
//     inliers, the residual (measured 7.2 mm rms) lies within 0.5-1.5 x the Kinect v1's random
//     depth error at the floor's distance (about 1.5 mm x z^2: 6.8 mm at 2.13 m) and under 1 cm.
//     A few millimetres is not on offer at 2.1 m from this sensor: its disparity steps alone
//     are about 1.2 cm there;
//  3. metric plausibility: the camera is 1.4-2.0 m above the floor (measured 1.73 m: a
//     hand-held camera at chest to head height) and the floor points are 1.9-2.5 m away;
//  4. the partition wall (u 320..460, v 20..100) is 2.5-2.9 m away (2.69 m) and perpendicular
//     to the floor within 6 degrees (2.0 degrees off): a check on the intrinsics, as a wrong
//     focal length or principal point would tilt the back-projected planes;
//  5. a wrong depth scale is detected: read as millimetres (1/1000, the common default) the
//     camera would be 7-10 m above the floor, and at 1/10000 m (off by 2) 0.7-1.0 m, both
//     outside the plausible range of check 3.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include <Eigen/Eigenvalues>

#include "pliant/vision/depth_cloud.hpp"
#include "pliant/vision/depth_image.hpp"

namespace pliant::vision {
namespace {

const std::string kDepthPng = std::string(PLIANT_TEST_DATA_DIR) + "/rgbd_tum/TUM_depth.png";
const PinholeIntrinsics kTum{517.3, 516.5, 318.6, 255.3, 640, 480};

struct Plane {
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();  ///< unit, toward the camera
  double distance = 0;                               ///< of the camera (the origin) from the plane, m
  double rms = 0;                                    ///< least-squares residual over the inliers, m
  double inlier_share = 0;
  double mean_depth = 0;
};

// RANSAC (fixed seed, 400 samples, `band` inlier half-width), then a least-squares refit (PCA)
// of the inliers.
Plane fit_plane(const DepthCloud& cloud, double band) {
  std::mt19937 rng(42);
  std::uniform_int_distribution<std::size_t> pick(0, cloud.size() - 1);
  auto point = [&](std::size_t i) { return Eigen::Vector3d(cloud.points[i].cast<double>()); };
  Eigen::Vector3d best_normal = Eigen::Vector3d::UnitZ();
  double best_offset = 0;
  std::size_t best_count = 0;
  for (int sample = 0; sample < 400; ++sample) {
    const Eigen::Vector3d a = point(pick(rng)), b = point(pick(rng)), c = point(pick(rng));
    const Eigen::Vector3d n = (b - a).cross(c - a);
    if (n.norm() < 1e-9) continue;
    const Eigen::Vector3d unit = n.normalized();
    std::size_t count = 0;
    for (std::size_t i = 0; i < cloud.size(); ++i) count += std::abs(unit.dot(point(i) - a)) < band ? 1u : 0u;
    if (count > best_count) {
      best_count = count;
      best_normal = unit;
      best_offset = unit.dot(a);
    }
  }
  std::vector<Eigen::Vector3d> inliers;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    if (std::abs(best_normal.dot(point(i)) - best_offset) < band) inliers.push_back(point(i));
  }
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const auto& p : inliers) centroid += p;
  centroid /= static_cast<double>(inliers.size());
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (const auto& p : inliers) scatter += (p - centroid) * (p - centroid).transpose();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(scatter);
  Plane plane;
  plane.normal = solver.eigenvectors().col(0);
  if (plane.normal.dot(centroid) > 0) plane.normal = -plane.normal;
  plane.distance = std::abs(plane.normal.dot(centroid));
  double sum = 0;
  for (const auto& p : inliers) sum += std::pow(plane.normal.dot(p - centroid), 2);
  plane.rms = std::sqrt(sum / static_cast<double>(inliers.size()));
  plane.inlier_share = static_cast<double>(inliers.size()) / static_cast<double>(cloud.size());
  plane.mean_depth = centroid.z();
  return plane;
}

DepthCloud region_cloud(const DepthImage& image, PixelRect region, double scale) {
  DepthToCloudOptions options;
  options.depth_scale_m = scale;
  options.region = region;
  DepthCloud cloud;
  depth_to_cloud(image.view(), kTum, options, cloud);
  return cloud;
}

const PixelRect kFloor{250, 435, 150, 35};
const PixelRect kWall{320, 20, 141, 81};

TEST(TumFrame, DecodesWithMostPixelsValid) {
  const DepthImage image = read_depth_png(kDepthPng);
  ASSERT_EQ(image.width, 640);
  ASSERT_EQ(image.height, 480);
  DepthToCloudOptions options;
  options.depth_scale_m = 1.0 / 5000;
  DepthCloud cloud;
  const std::size_t valid = depth_to_cloud(image.view(), kTum, options, cloud);
  EXPECT_GT(valid, 640u * 480u * 3 / 4);
  EXPECT_LT(valid, 640u * 480u * 9 / 10);
  for (const auto& p : cloud.points) {
    ASSERT_GT(p.z(), 0.4f);   // the Kinect's near limit
    ASSERT_LT(p.z(), 10.0f);  // and its far one
  }
}

TEST(TumFrame, FloorIsAPlaneAtAPlausibleHeight) {
  const DepthImage image = read_depth_png(kDepthPng);
  const Plane floor = fit_plane(region_cloud(image, kFloor, 1.0 / 5000), 0.02);
  EXPECT_GT(floor.inlier_share, 0.95);
  // The residual is the sensor's random depth error at that distance (Kinect v1: about
  // 1.5 mm x z^2, z in m; measured 7.2 mm at 2.13 m against 6.8 mm from that model).
  const double sensor_sd = 1.5e-3 * floor.mean_depth * floor.mean_depth;
  EXPECT_GT(floor.rms, 0.5 * sensor_sd);
  EXPECT_LT(floor.rms, 1.5 * sensor_sd);
  EXPECT_LT(floor.rms, 0.01);
  EXPECT_GT(floor.distance, 1.4);
  EXPECT_LT(floor.distance, 2.0);
  EXPECT_GT(floor.mean_depth, 1.9);
  EXPECT_LT(floor.mean_depth, 2.5);
  // Image y points down and the floor is below the camera: its normal (toward the camera)
  // points up, i.e. mostly along -y.
  EXPECT_LT(floor.normal.y(), -0.8);

  const Plane wall = fit_plane(region_cloud(image, kWall, 1.0 / 5000), 0.03);
  EXPECT_GT(wall.distance, 2.5);
  EXPECT_LT(wall.distance, 2.9);
  EXPECT_LT(std::abs(wall.normal.dot(floor.normal)), std::sin(6.0 * 3.14159265358979 / 180));
}

TEST(TumFrame, AWrongDepthScaleIsImplausible) {
  const DepthImage image = read_depth_png(kDepthPng);
  const double right = fit_plane(region_cloud(image, kFloor, 1.0 / 5000), 0.02).distance;
  const double millimetres = fit_plane(region_cloud(image, kFloor, 1.0 / 1000), 0.1).distance;
  const double half = fit_plane(region_cloud(image, kFloor, 1.0 / 10000), 0.01).distance;
  EXPECT_NEAR(millimetres / right, 5.0, 0.05);
  EXPECT_NEAR(half / right, 0.5, 0.01);
  EXPECT_GT(millimetres, 7.0);
  EXPECT_LT(millimetres, 10.0);
  EXPECT_GT(half, 0.7);
  EXPECT_LT(half, 1.0);
  // Neither passes the plausibility range of FloorIsAPlaneAtAPlausibleHeight.
  EXPECT_FALSE(millimetres > 1.4 && millimetres < 2.0);
  EXPECT_FALSE(half > 1.4 && half < 2.0);
}

}  // namespace
}  // namespace pliant::vision
