#include "pliant/drivers/openni2/depth_points.hpp"

#include <cmath>
#include <cstring>

#include "pliant/hal/depth_projection.hpp"

namespace pliant::drivers::openni2 {
namespace {

bool size_ok(int width, int height) noexcept {
  return width >= 1 && height >= 1 && width <= kMaxDepthSide && height <= kMaxDepthSide;
}

bool finite_positive(double value) noexcept { return std::isfinite(value) && value > 0; }

bool focal_ok(double value) noexcept { return std::isfinite(value) && value >= kMinFocalPx && value <= kMaxFocalPx; }

bool angle_ok(double angle_rad) noexcept {
  return std::isfinite(angle_rad) && angle_rad > kMinFovRad && angle_rad < kMaxFovRad;
}

// Sizes are bounded by kMaxDepthSide, so these products cannot overflow std::size_t.
bool layout_ok(std::size_t bytes, int width, int height, std::size_t stride_bytes, PointsStatus& status) noexcept {
  if (!size_ok(width, height)) {
    status = PointsStatus::bad_size;
    return false;
  }
  const std::size_t row_bytes = 2 * static_cast<std::size_t>(width);
  if (stride_bytes < row_bytes) {
    status = PointsStatus::bad_stride;
    return false;
  }
  // Divide before multiplying: a huge stride times the rows could wrap around.
  const std::size_t rows_before_last = static_cast<std::size_t>(height) - 1;
  if (rows_before_last != 0 && stride_bytes > bytes / rows_before_last) {
    status = PointsStatus::buffer_too_small;
    return false;
  }
  if (bytes - rows_before_last * stride_bytes < row_bytes) {
    status = PointsStatus::buffer_too_small;
    return false;
  }
  return true;
}

template <typename Scalar>
PointsResult back_project(const std::uint8_t* depth, std::size_t depth_bytes, int width, int height,
                          std::size_t stride_bytes, double depth_scale_m, const DepthIntrinsics& k, Scalar* out,
                          std::size_t out_capacity_points) noexcept {
  PointsResult result;
  if (!layout_ok(depth_bytes, width, height, stride_bytes, result.status)) return result;
  if (depth == nullptr) {
    result.status = PointsStatus::buffer_too_small;
    return result;
  }
  if (!std::isfinite(depth_scale_m) || depth_scale_m <= 0 || depth_scale_m > 1) {
    result.status = PointsStatus::bad_scale;
    return result;
  }
  if (check_intrinsics(k) != IntrinsicsCheck::ok || k.width != width || k.height != height) {
    result.status = PointsStatus::bad_intrinsics;
    return result;
  }
  const std::size_t pixels = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  if (out == nullptr || out_capacity_points < pixels) {
    result.status = PointsStatus::output_too_small;
    return result;
  }
  // The HAL's back-projection (depth_projection.hpp): an organised cloud, NaN where raw is 0.
  const hal::DepthRaster raster{depth, stride_bytes};
  const hal::DepthPinhole pinhole{k.fx, k.fy, k.cx, k.cy, depth_scale_m};
  const hal::DepthWindow window{0, 0, width, height, 1};
  Scalar* point = out;
  hal::back_project_depth(raster, pinhole, window, [&](const hal::DepthPoint& p) noexcept {
    point[0] = static_cast<Scalar>(p.x);
    point[1] = static_cast<Scalar>(p.y);
    point[2] = static_cast<Scalar>(p.z);
    point += 3;
    if (p.raw != 0) ++result.valid_points;
  });
  return result;
}

}  // namespace

const char* intrinsics_check_name(IntrinsicsCheck check) noexcept {
  switch (check) {
    case IntrinsicsCheck::ok: return "ok";
    case IntrinsicsCheck::bad_size: return "bad_size";
    case IntrinsicsCheck::bad_fov: return "bad_fov";
    case IntrinsicsCheck::aspect_mismatch: return "aspect_mismatch";
    case IntrinsicsCheck::bad_focal: return "bad_focal";
    case IntrinsicsCheck::bad_principal: return "bad_principal";
  }
  return "unknown";
}

const char* points_status_name(PointsStatus status) noexcept {
  switch (status) {
    case PointsStatus::ok: return "ok";
    case PointsStatus::bad_size: return "bad_size";
    case PointsStatus::bad_stride: return "bad_stride";
    case PointsStatus::buffer_too_small: return "buffer_too_small";
    case PointsStatus::bad_scale: return "bad_scale";
    case PointsStatus::bad_intrinsics: return "bad_intrinsics";
    case PointsStatus::output_too_small: return "output_too_small";
  }
  return "unknown";
}

bool fov_is_valid(double hfov_rad, double vfov_rad) noexcept { return angle_ok(hfov_rad) && angle_ok(vfov_rad); }

IntrinsicsCheck intrinsics_from_fov(double hfov_rad, double vfov_rad, int width, int height,
                                    DepthIntrinsics& out) noexcept {
  if (!size_ok(width, height)) return IntrinsicsCheck::bad_size;
  if (!fov_is_valid(hfov_rad, vfov_rad)) return IntrinsicsCheck::bad_fov;
  const double fx = 0.5 * width / std::tan(0.5 * hfov_rad);
  const double fy = 0.5 * height / std::tan(0.5 * vfov_rad);
  if (!finite_positive(fx) || !finite_positive(fy)) return IntrinsicsCheck::bad_fov;
  const double ratio = fx / fy;
  if (ratio > kMaxFocalRatio || ratio < 1.0 / kMaxFocalRatio) return IntrinsicsCheck::aspect_mismatch;
  out.fx = fx;
  out.fy = fy;
  out.cx = 0.5 * (width - 1);
  out.cy = 0.5 * (height - 1);
  out.width = width;
  out.height = height;
  return IntrinsicsCheck::ok;
}

IntrinsicsCheck check_intrinsics(const DepthIntrinsics& k) noexcept {
  if (!size_ok(k.width, k.height)) return IntrinsicsCheck::bad_size;
  if (!focal_ok(k.fx) || !focal_ok(k.fy)) return IntrinsicsCheck::bad_focal;
  const double w = k.width, h = k.height;
  if (!std::isfinite(k.cx) || !std::isfinite(k.cy) || k.cx < -w || k.cx > 2 * w || k.cy < -h || k.cy > 2 * h) {
    return IntrinsicsCheck::bad_principal;
  }
  return IntrinsicsCheck::ok;
}

PointsResult depth_to_points(const std::uint8_t* depth, std::size_t depth_bytes, int width, int height,
                             std::size_t stride_bytes, double depth_scale_m, const DepthIntrinsics& intrinsics,
                             double* out_xyz, std::size_t out_capacity_points) noexcept {
  return back_project(depth, depth_bytes, width, height, stride_bytes, depth_scale_m, intrinsics, out_xyz,
                      out_capacity_points);
}

PointsResult depth_to_points(const std::uint8_t* depth, std::size_t depth_bytes, int width, int height,
                             std::size_t stride_bytes, double depth_scale_m, const DepthIntrinsics& intrinsics,
                             float* out_xyz, std::size_t out_capacity_points) noexcept {
  return back_project(depth, depth_bytes, width, height, stride_bytes, depth_scale_m, intrinsics, out_xyz,
                      out_capacity_points);
}

PointsResult depth_to_points(const hal::DepthFrame& frame, double* out_xyz, std::size_t out_capacity_points) noexcept {
  PointsResult result;
  if (!size_ok(frame.width, frame.height) || frame.stride_bytes < 0) {
    result.status = PointsStatus::bad_size;
    return result;
  }
  const DepthIntrinsics k{frame.fx, frame.fy, frame.cx, frame.cy, frame.width, frame.height};
  const std::size_t stride = static_cast<std::size_t>(frame.stride_bytes);
  const std::size_t bytes = stride * static_cast<std::size_t>(frame.height);
  return back_project(reinterpret_cast<const std::uint8_t*>(frame.data), bytes, frame.width, frame.height, stride,
                      frame.depth_scale_m, k, out_xyz, out_capacity_points);
}

bool copy_depth_image(const std::uint8_t* src, std::size_t src_bytes, int width, int height, std::size_t stride_bytes,
                      std::uint16_t* dst, std::size_t dst_capacity) noexcept {
  PointsStatus status = PointsStatus::ok;
  if (src == nullptr || dst == nullptr || !layout_ok(src_bytes, width, height, stride_bytes, status)) return false;
  const std::size_t w = static_cast<std::size_t>(width);
  if (dst_capacity < w * static_cast<std::size_t>(height)) return false;
  if (stride_bytes == 2 * w) {
    std::memcpy(dst, src, 2 * w * static_cast<std::size_t>(height));
    return true;
  }
  for (int v = 0; v < height; ++v) {
    std::memcpy(dst + static_cast<std::size_t>(v) * w, src + static_cast<std::size_t>(v) * stride_bytes, 2 * w);
  }
  return true;
}

}  // namespace pliant::drivers::openni2
