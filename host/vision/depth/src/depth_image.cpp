#include "pliant/vision/depth_image.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "pliant/hal/camera.hpp"

namespace pliant::vision {
namespace {

bool finite_positive(double value) { return std::isfinite(value) && value > 0; }

}  // namespace

void check_intrinsics(const PinholeIntrinsics& k) {
  if (!finite_positive(k.fx)) throw DepthError("intrinsics: fx must be finite and > 0 (missing intrinsics?)");
  if (!finite_positive(k.fy)) throw DepthError("intrinsics: fy must be finite and > 0 (missing intrinsics?)");
  if (!std::isfinite(k.cx)) throw DepthError("intrinsics: cx must be finite");
  if (!std::isfinite(k.cy)) throw DepthError("intrinsics: cy must be finite");
  if (k.width < 1 || k.height < 1) throw DepthError("intrinsics: image width and height must be >= 1");
}

DepthImageView depth_view(const hal::DepthFrame& frame) {
  if (frame.data == nullptr) throw DepthError("depth frame: no data");
  if (frame.width < 1 || frame.height < 1) throw DepthError("depth frame: width and height must be >= 1");
  if (frame.stride_bytes < 2 * frame.width || frame.stride_bytes % 2 != 0) {
    throw DepthError("depth frame: stride_bytes must be even and >= 2 x width");
  }
  return {frame.data, frame.width, frame.height, static_cast<std::size_t>(frame.stride_bytes / 2)};
}

PinholeIntrinsics intrinsics_of(const hal::DepthFrame& frame) {
  PinholeIntrinsics k{frame.fx, frame.fy, frame.cx, frame.cy, frame.width, frame.height};
  if (std::isnan(k.fx) || std::isnan(k.fy) || std::isnan(k.cx) || std::isnan(k.cy)) {
    throw DepthError("depth frame: the device reports no intrinsics (give them explicitly)");
  }
  check_intrinsics(k);
  return k;
}

}  // namespace pliant::vision
