// drivers/openni2: the per-frame functions (frame copy, back-projection, intrinsics) never touch
// the heap, proven with the counting allocator. (read() itself is not measured this way: the
// counter is process-wide and OpenNI2's own threads allocate while they decode.)
#include <gtest/gtest.h>

#include <vector>

#include "pliant/drivers/openni2/depth_points.hpp"
#include "support/counting_allocator.hpp"

namespace {

using namespace pliant::drivers::openni2;

TEST(Openni2Allocation, PerFrameFunctionsAreAllocationFree) {
  const int width = 64, height = 48;
  const std::size_t stride = 2 * width + 6;
  std::vector<std::uint8_t> image(stride * height);
  for (std::size_t i = 0; i < image.size(); ++i) image[i] = static_cast<std::uint8_t>(i * 7);
  std::vector<std::uint16_t> packed(static_cast<std::size_t>(width) * height);
  std::vector<double> xyz(packed.size() * 3);
  std::vector<float> xyz_f(packed.size() * 3);
  DepthIntrinsics k;
  bool copied = false;
  PointsResult points, points_f;
  IntrinsicsCheck check = IntrinsicsCheck::bad_size;

  pliant::test::AllocationCounter counter;
  check = intrinsics_from_fov(1.0, 0.78, width, height, k);
  copied = copy_depth_image(image.data(), image.size(), width, height, stride, packed.data(), packed.size());
  points = depth_to_points(image.data(), image.size(), width, height, stride, 1e-3, k, xyz.data(), packed.size());
  points_f = depth_to_points(image.data(), image.size(), width, height, stride, 1e-4, k, xyz_f.data(), packed.size());
  const pliant::test::AllocationCounts counts = counter.stop();

  EXPECT_EQ(check, IntrinsicsCheck::ok);
  EXPECT_TRUE(copied);
  EXPECT_EQ(points.status, PointsStatus::ok);
  EXPECT_EQ(points_f.status, PointsStatus::ok);
  EXPECT_GT(points.valid_points, 0u);
  EXPECT_EQ(counts.total(), 0u) << "news " << counts.news << ", mallocs " << counts.mallocs;
}

}  // namespace
