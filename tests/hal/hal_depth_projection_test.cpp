// The HAL's depth back-projection: analytic points, NaNs where there is no measurement, windows
// and steps (including a step far larger than the image), unaligned rows with padding.
#include <gtest/gtest.h>

#include <climits>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <vector>

#include "pliant/hal/depth_projection.hpp"

namespace pliant::hal {
namespace {

// A width x height raster of `raw` samples whose rows are `stride_bytes` apart, starting one byte
// into the buffer (so no sample is aligned).
struct Raster {
  std::vector<std::uint8_t> bytes;
  DepthRaster view;
  Raster(const std::vector<std::uint16_t>& raw, int width, int height, std::size_t stride_bytes)
      : bytes(1 + stride_bytes * static_cast<std::size_t>(height), 0xEE) {
    for (int v = 0; v < height; ++v) {
      std::memcpy(bytes.data() + 1 + static_cast<std::size_t>(v) * stride_bytes,
                  raw.data() + static_cast<std::size_t>(v) * static_cast<std::size_t>(width),
                  2 * static_cast<std::size_t>(width));
    }
    view = {bytes.data() + 1, stride_bytes};
  }
};

std::vector<DepthPoint> visit_all(const DepthRaster& raster, const DepthPinhole& k, const DepthWindow& window) {
  std::vector<DepthPoint> points;
  back_project_depth(raster, k, window, [&](const DepthPoint& p) { points.push_back(p); });
  return points;
}

TEST(HalDepthProjection, PinholeFormulaAndMissingPixels) {
  const Raster raster({1000, 0, 2000, 500, 1500, 0}, 3, 2, 8);
  const DepthPinhole k{100, 200, 1, 0.5, 1e-3};
  const std::vector<DepthPoint> points = visit_all(raster.view, k, {0, 0, 3, 2, 1});
  ASSERT_EQ(points.size(), 6u);
  EXPECT_EQ(points[0].u, 0);
  EXPECT_EQ(points[0].v, 0);
  EXPECT_DOUBLE_EQ(points[0].x, (0 - 1) / 100.0 * 1.0);
  EXPECT_DOUBLE_EQ(points[0].y, (0 - 0.5) / 200.0 * 1.0);
  EXPECT_DOUBLE_EQ(points[0].z, 1.0);
  EXPECT_EQ(points[1].raw, 0);
  EXPECT_TRUE(std::isnan(points[1].x) && std::isnan(points[1].y) && std::isnan(points[1].z));
  EXPECT_DOUBLE_EQ(points[2].x, (2 - 1) / 100.0 * 2.0);
  EXPECT_EQ(points[4].u, 1);
  EXPECT_EQ(points[4].v, 1);
  EXPECT_DOUBLE_EQ(points[4].y, (1 - 0.5) / 200.0 * 1.5);
  EXPECT_TRUE(std::isnan(points[5].z));
}

TEST(HalDepthProjection, WindowAndStepInRowMajorOrder) {
  std::vector<std::uint16_t> raw(5 * 4);
  for (std::size_t i = 0; i < raw.size(); ++i) raw[i] = static_cast<std::uint16_t>(i + 1);
  const Raster raster(raw, 5, 4, 12);
  const DepthPinhole k{50, 50, 2, 1.5, 1e-3};
  const std::vector<DepthPoint> points = visit_all(raster.view, k, {1, 1, 4, 3, 2});
  ASSERT_EQ(points.size(), 4u);  // columns 1, 3 of rows 1, 3
  const int want[4][2] = {{1, 1}, {3, 1}, {1, 3}, {3, 3}};
  for (std::size_t i = 0; i < points.size(); ++i) {
    EXPECT_EQ(points[i].u, want[i][0]);
    EXPECT_EQ(points[i].v, want[i][1]);
    EXPECT_EQ(points[i].raw, raw[static_cast<std::size_t>(want[i][1] * 5 + want[i][0])]);
  }
  // A step near INT_MAX visits the corner alone; an empty window visits nothing.
  EXPECT_EQ(visit_all(raster.view, k, {0, 0, 5, 4, INT_MAX}).size(), 1u);
  EXPECT_TRUE(visit_all(raster.view, k, {0, 0, 0, 4, 1}).empty());
}

}  // namespace
}  // namespace pliant::hal
