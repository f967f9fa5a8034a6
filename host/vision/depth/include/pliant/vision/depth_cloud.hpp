// Depth image -> metric point cloud in the camera (optical) frame (see depth_image.hpp for the
// frame and the pinhole model).
//
// Memory: DepthCloud keeps its vectors between frames; depth_to_cloud clears and refills them,
// so once reserve(cloud_capacity(...)) has run a conversion allocates nothing.
// Thread safety: none needed (no shared state); one cloud per thread.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

#include <Eigen/Core>

#include "pliant/vision/depth_image.hpp"

namespace pliant::vision {

/// A pixel rectangle: columns u0 .. u0 + width - 1, rows v0 .. v0 + height - 1. An empty
/// rectangle (width or height 0) means the whole image.
struct PixelRect {
  int u0 = 0;
  int v0 = 0;
  int width = 0;
  int height = 0;
  bool empty() const noexcept { return width == 0 || height == 0; }
};

struct DepthToCloudOptions {
  /// Metres per raw depth unit, finite > 0: 1e-3 for millimetres (OpenNI2, RealSense, Kinect),
  /// 2e-4 for the TUM RGB-D benchmark (5000 units per metre).
  double depth_scale_m = 1e-3;
  int stride = 1;            ///< >= 1: every stride-th column and row, counted from the region's corner
  PixelRect region;          ///< region of interest; empty = the whole image; must lie inside the image
  double min_depth_m = 0.0;  ///< >= 0: nearer points are dropped (sensor blind zone)
  double max_depth_m = std::numeric_limits<double>::infinity();  ///< > min_depth_m: farther dropped
};

/// Points of one depth image, in the camera frame (m). points[k] came from the image pixel
/// pixel[k] = v * width + u. Points are in row-major pixel order.
struct DepthCloud {
  std::vector<Eigen::Vector3f> points;
  std::vector<std::int32_t> pixel;
  int image_width = 0;  ///< of the image the cloud came from
  int image_height = 0;
  std::size_t size() const noexcept { return points.size(); }
  /// Reserves room for `count` points so later conversions do not allocate.
  void reserve(std::size_t count) {
    points.reserve(count);
    pixel.reserve(count);
  }
};

/// Most points a conversion of a width x height image with `options` can yield (the pixels of
/// the region at the stride).
std::size_t cloud_capacity(int width, int height, const DepthToCloudOptions& options) noexcept;

/// Throws DepthError unless `image`, `intrinsics` and `options` fit together: intrinsics valid
/// (check_intrinsics), image data present and of the intrinsics' size ("depth image is 320x240
/// but the intrinsics are for 640x480"), row_stride >= width, options valid (scale finite > 0,
/// stride >= 1, 0 <= min_depth_m < max_depth_m, region inside the image).
void check_depth_input(const DepthImageView& image, const PinholeIntrinsics& intrinsics,
                       const DepthToCloudOptions& options);

/// The option checks of check_depth_input for a width x height image (also refuses images of
/// more than 2^31 - 1 pixels). Throws DepthError.
void check_cloud_options(const DepthToCloudOptions& options, int width, int height);

/// Converts `image` into `out` (cleared first): every pixel of the region at the stride whose raw
/// depth is non-zero and whose metric depth lies in [min_depth_m, max_depth_m]. Returns the
/// point count. Throws DepthError for inputs check_depth_input refuses, and when no pixel is
/// valid ("depth image has no valid pixel in the region (all zero or out of range)"): an empty
/// frame is an error here; DepthTracker treats it as a frame without observations instead.
/// Allocates only when out's capacity is below cloud_capacity(). O(region pixels / stride^2).
std::size_t depth_to_cloud(const DepthImageView& image, const PinholeIntrinsics& intrinsics,
                           const DepthToCloudOptions& options, DepthCloud& out);

/// The same without the checks and without the empty-frame error (the caller has run
/// check_depth_input for this geometry). Returns the point count, 0 for an empty frame.
/// Throws only std::bad_alloc, and only when out's capacity is below cloud_capacity().
std::size_t depth_to_cloud_unchecked(const DepthImageView& image, const PinholeIntrinsics& intrinsics,
                                     const DepthToCloudOptions& options, DepthCloud& out);

}  // namespace pliant::vision
