#include "pliant/vision/depth_cloud.hpp"

#include <cmath>
#include <limits>
#include <string>

#include "pliant/hal/depth_projection.hpp"

namespace pliant::vision {
namespace {

PixelRect region_of(const DepthToCloudOptions& options, int width, int height) noexcept {
  return options.region.empty() ? PixelRect{0, 0, width, height} : options.region;
}

std::string size_text(int width, int height) { return std::to_string(width) + "x" + std::to_string(height); }

}  // namespace

std::size_t cloud_capacity(int width, int height, const DepthToCloudOptions& options) noexcept {
  if (width < 1 || height < 1 || options.stride < 1) return 0;
  const PixelRect r = region_of(options, width, height);
  if (r.width < 1 || r.height < 1) return 0;
  // In 64 bits: a stride near INT_MAX must not overflow the rounding up.
  const long long stride = options.stride;
  const auto columns = static_cast<std::size_t>((r.width + stride - 1) / stride);
  const auto rows = static_cast<std::size_t>((r.height + stride - 1) / stride);
  return columns * rows;
}

void check_depth_input(const DepthImageView& image, const PinholeIntrinsics& intrinsics,
                       const DepthToCloudOptions& options) {
  check_intrinsics(intrinsics);
  if (image.data == nullptr) throw DepthError("depth image: no data");
  if (image.width < 1 || image.height < 1)
    throw DepthError("depth image: empty (" + size_text(image.width, image.height) + ")");
  if (image.width != intrinsics.width || image.height != intrinsics.height) {
    throw DepthError("depth image is " + size_text(image.width, image.height) + " but the intrinsics are for " +
                     size_text(intrinsics.width, intrinsics.height));
  }
  if (image.stride() < static_cast<std::size_t>(image.width))
    throw DepthError("depth image: row_stride is smaller than the width");
  check_cloud_options(options, image.width, image.height);
}

void check_cloud_options(const DepthToCloudOptions& options, int width, int height) {
  if (width < 1 || height < 1 ||
      static_cast<long long>(width) * static_cast<long long>(height) > std::numeric_limits<std::int32_t>::max()) {
    throw DepthError("depth image: size " + size_text(width, height) + " out of range");
  }
  if (!(std::isfinite(options.depth_scale_m) && options.depth_scale_m > 0)) {
    throw DepthError("depth options: depth_scale_m must be finite and > 0");
  }
  if (options.stride < 1) throw DepthError("depth options: stride must be >= 1");
  if (!(std::isfinite(options.min_depth_m) && options.min_depth_m >= 0)) {
    throw DepthError("depth options: min_depth_m must be finite and >= 0");
  }
  if (!(options.max_depth_m > options.min_depth_m))
    throw DepthError("depth options: max_depth_m must exceed min_depth_m");
  if (!options.region.empty()) {
    const PixelRect& r = options.region;
    if (r.u0 < 0 || r.v0 < 0 || r.width < 0 || r.height < 0 || r.width > width - r.u0 || r.height > height - r.v0) {
      throw DepthError("depth options: region " + std::to_string(r.u0) + "," + std::to_string(r.v0) + "," +
                       size_text(r.width, r.height) + " is not inside the " + size_text(width, height) + " image");
    }
  }
}

std::size_t depth_to_cloud_unchecked(const DepthImageView& image, const PinholeIntrinsics& k,
                                     const DepthToCloudOptions& options, DepthCloud& out) {
  out.points.clear();
  out.pixel.clear();
  out.image_width = image.width;
  out.image_height = image.height;
  const std::size_t capacity = cloud_capacity(image.width, image.height, options);
  if (out.points.capacity() < capacity) out.reserve(capacity);
  const PixelRect r = region_of(options, image.width, image.height);
  // The HAL's back-projection (hal/depth_projection.hpp), the one the depth drivers use.
  const hal::DepthRaster raster{reinterpret_cast<const std::uint8_t*>(image.data),
                                image.stride() * sizeof(std::uint16_t)};
  const hal::DepthPinhole pinhole{k.fx, k.fy, k.cx, k.cy, options.depth_scale_m};
  const hal::DepthWindow window{r.u0, r.v0, r.width, r.height, options.stride};
  hal::back_project_depth(raster, pinhole, window, [&](const hal::DepthPoint& p) {
    if (p.raw == 0 || p.z < options.min_depth_m || p.z > options.max_depth_m) return;
    out.points.emplace_back(static_cast<float>(p.x), static_cast<float>(p.y), static_cast<float>(p.z));
    out.pixel.push_back(p.v * image.width + p.u);
  });
  return out.points.size();
}

std::size_t depth_to_cloud(const DepthImageView& image, const PinholeIntrinsics& intrinsics,
                           const DepthToCloudOptions& options, DepthCloud& out) {
  check_depth_input(image, intrinsics, options);
  const std::size_t count = depth_to_cloud_unchecked(image, intrinsics, options, out);
  if (count == 0) throw DepthError("depth image has no valid pixel in the region (all zero or out of range)");
  return count;
}

}  // namespace pliant::vision
