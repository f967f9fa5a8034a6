// pliant hal: pinhole back-projection of depth images to points. The one implementation in
// pliant: drivers/openni2's depth_to_points (organised clouds for any HAL depth frame) and the
// depth front end's depth_to_cloud (host/vision/depth) both visit their pixels through it, so a
// pixel becomes the same point, to the bit, whichever path it takes.
//
// Camera (optical) frame, metres: x to the right of the image, y down, z forward along the
// optical axis. Pixel (u, v) is column u, row v, and integer coordinates are pixel centres. A
// pixel with raw depth d > 0 back-projects to
//   z = d * depth_scale_m,  X = ((u - cx) z / fx, (v - cy) z / fy, z)
// in double precision, with the reciprocals 1 / fx and 1 / fy taken once per call. Raw 0 means
// no measurement; such a pixel is visited too, with three quiet NaNs.
//
// No checks here: the caller has made sure that every visited row lies inside the buffer, that
// the focal lengths are finite and non-zero and the scale finite (the driver and the front end
// each report malformed input in their own terms: a status, or an exception on the host).
//
// Real-time safety: header-only, allocation-free, O(visited pixels); noexcept when the visitor
// is. Thread safety: pure; safe from any thread on distinct outputs.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>
#include <utility>

namespace pliant::hal {

/// Pinhole intrinsics of a depth image, px, and the size of one raw depth unit, m.
struct DepthPinhole {
  double fx = 0;
  double fy = 0;
  double cx = 0;
  double cy = 0;
  double depth_scale_m = 1e-3;
};

/// Raw depths: native-endian uint16 samples, row v starting at bytes + v * stride_bytes. The
/// samples need not be aligned.
struct DepthRaster {
  const std::uint8_t* bytes = nullptr;
  std::size_t stride_bytes = 0;
};

/// The pixels visited: columns u0, u0 + step, ... below u0 + width; rows v0, v0 + step, ...
/// below v0 + height (row-major order). u0, v0 >= 0, step >= 1.
struct DepthWindow {
  int u0 = 0;
  int v0 = 0;
  int width = 0;
  int height = 0;
  int step = 1;
};

/// One visited pixel.
struct DepthPoint {
  int u = 0;
  int v = 0;
  std::uint16_t raw = 0;  ///< 0: no measurement (x, y, z are then quiet NaNs)
  double x = 0;
  double y = 0;
  double z = 0;
};

/// Calls visit(const DepthPoint&) for every pixel of `window`, in row-major order.
template <typename Visit>
void back_project_depth(const DepthRaster& raster, const DepthPinhole& k, const DepthWindow& window,
                        Visit&& visit) noexcept(noexcept(visit(std::declval<const DepthPoint&>()))) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inverse_fx = 1.0 / k.fx;
  const double inverse_fy = 1.0 / k.fy;
  // 64-bit counters: a step near INT_MAX cannot overflow them.
  const long long u_end = static_cast<long long>(window.u0) + window.width;
  const long long v_end = static_cast<long long>(window.v0) + window.height;
  DepthPoint point;
  for (long long v = window.v0; v < v_end; v += window.step) {
    const std::uint8_t* row = raster.bytes + static_cast<std::size_t>(v) * raster.stride_bytes;
    const double ray_y = (static_cast<double>(v) - k.cy) * inverse_fy;
    point.v = static_cast<int>(v);
    for (long long u = window.u0; u < u_end; u += window.step) {
      std::memcpy(&point.raw, row + 2 * static_cast<std::size_t>(u), sizeof point.raw);
      point.u = static_cast<int>(u);
      if (point.raw == 0) {
        point.x = point.y = point.z = nan;
      } else {
        const double z = static_cast<double>(point.raw) * k.depth_scale_m;
        point.x = (static_cast<double>(u) - k.cx) * inverse_fx * z;
        point.y = ray_y * z;
        point.z = z;
      }
      visit(static_cast<const DepthPoint&>(point));
    }
  }
}

}  // namespace pliant::hal
