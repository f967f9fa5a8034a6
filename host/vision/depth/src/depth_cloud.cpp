#include "pliant/vision/depth_cloud.hpp"

#include <cmath>
#include <limits>
#include <string>

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
  const auto columns = static_cast<std::size_t>((r.width + options.stride - 1) / options.stride);
  const auto rows = static_cast<std::size_t>((r.height + options.stride - 1) / options.stride);
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
  const double scale = options.depth_scale_m;
  const double inverse_fx = 1.0 / k.fx;
  const double inverse_fy = 1.0 / k.fy;
  for (int v = r.v0; v < r.v0 + r.height; v += options.stride) {
    const double ray_y = (static_cast<double>(v) - k.cy) * inverse_fy;
    const std::uint16_t* row = image.data + static_cast<std::size_t>(v) * image.stride();
    for (int u = r.u0; u < r.u0 + r.width; u += options.stride) {
      const std::uint16_t raw = row[u];
      if (raw == 0) continue;
      const double z = static_cast<double>(raw) * scale;
      if (z < options.min_depth_m || z > options.max_depth_m) continue;
      const double x = (static_cast<double>(u) - k.cx) * inverse_fx * z;
      out.points.emplace_back(static_cast<float>(x), static_cast<float>(ray_y * z), static_cast<float>(z));
      out.pixel.push_back(v * image.width + u);
    }
  }
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
