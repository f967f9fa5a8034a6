// pliant drivers/openni2: pinhole intrinsics from a field of view, and depth images to 3D points.
// Pure functions with no OpenNI2 dependency: any depth camera's frames can use them.
//
// Camera (optical) frame, metres: x to the right of the image, y down, z forward along the
// optical axis. Pixel (u, v) is column u, row v, and integer coordinates are pixel centres (the
// convention of pliant::vision). A pixel with raw depth d back-projects to
//   z = d * depth_scale_m,  X = ((u - cx) z / fx, (v - cy) z / fy, z).
//
// Intrinsics from a field of view (what OpenNI2 reports, as full angles in radians):
//   fx = (width / 2) / tan(hfov / 2),  fy = (height / 2) / tan(vfov / 2),
//   cx = (width - 1) / 2,              cy = (height - 1) / 2
// i.e. the angle spans the image from the left edge of pixel 0 to the right edge of the last
// pixel. OpenNI2's own CoordinateConverter puts the centre at width / 2 (half a pixel to the
// right and down) and points y up; tests/drivers/openni2 checks the two agree once both are
// accounted for.
//
// Validity of a field of view: both angles finite and inside (kMinFovRad, kMaxFovRad), and the
// two focal lengths within a factor kMaxFocalRatio of each other (pixels that far from square
// mean the angles do not belong together). OpenNI2 devices that do not implement the FOV
// property (Debian's DummyDevice) report 0, which fails the check: the driver then uses
// configured intrinsics instead.
//
// Real-time safety: every function here is O(1) or O(pixels), allocation-free and noexcept.
// Thread safety: pure; safe from any thread on distinct outputs.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>

#include "pliant/hal/camera.hpp"

namespace pliant::drivers::openni2 {

/// Largest accepted image side, px (also bounds every size computation here).
inline constexpr int kMaxDepthSide = 16384;
/// Open interval of accepted full field-of-view angles, radians (1 and 179 degrees).
inline constexpr double kMinFovRad = 0.017453292519943295;
inline constexpr double kMaxFovRad = 3.12413936106985;
/// Largest accepted fx / fy (or fy / fx) for intrinsics derived from a field of view.
inline constexpr double kMaxFocalRatio = 2.0;
/// Accepted focal lengths, px (keeps every back-projected coordinate finite, even in float).
inline constexpr double kMinFocalPx = 1e-3;
inline constexpr double kMaxFocalPx = 1e9;

/// Pinhole intrinsics of a depth image of width x height pixels (no distortion).
struct DepthIntrinsics {
  double fx = std::numeric_limits<double>::quiet_NaN();  ///< focal length along u, px
  double fy = std::numeric_limits<double>::quiet_NaN();  ///< focal length along v, px
  double cx = std::numeric_limits<double>::quiet_NaN();  ///< principal point column, px
  double cy = std::numeric_limits<double>::quiet_NaN();  ///< principal point row, px
  int width = 0;                                         ///< the image size these are for, px
  int height = 0;
};

enum class IntrinsicsCheck : std::uint8_t {
  ok,
  bad_size,         ///< width or height outside 1..kMaxDepthSide
  bad_fov,          ///< an angle not finite or outside (kMinFovRad, kMaxFovRad)
  aspect_mismatch,  ///< fx / fy outside [1 / kMaxFocalRatio, kMaxFocalRatio]
  bad_focal,        ///< fx or fy not finite or outside [kMinFocalPx, kMaxFocalPx]
  bad_principal,    ///< cx or cy not finite, or farther than one image size outside the image
};

/// Short stable name ("ok", "bad_fov", ...).
const char* intrinsics_check_name(IntrinsicsCheck check) noexcept;

/// True when both angles (radians) are usable (see the header comment); false for NaN, 0, ...
bool fov_is_valid(double hfov_rad, double vfov_rad) noexcept;

/// Intrinsics of a width x height image from its fields of view (formulas above). `out` is
/// written only when the result is ok.
IntrinsicsCheck intrinsics_from_fov(double hfov_rad, double vfov_rad, int width, int height,
                                    DepthIntrinsics& out) noexcept;

/// Checks intrinsics given by a user: size, focal lengths within [kMinFocalPx, kMaxFocalPx],
/// finite principal point within [-size, 2 * size] on each axis.
IntrinsicsCheck check_intrinsics(const DepthIntrinsics& intrinsics) noexcept;

enum class PointsStatus : std::uint8_t {
  ok,
  bad_size,          ///< width or height outside 1..kMaxDepthSide
  bad_stride,        ///< stride_bytes < 2 * width
  buffer_too_small,  ///< depth_bytes < (height - 1) * stride_bytes + 2 * width
  bad_scale,         ///< depth_scale_m not finite or outside (0, 1]
  bad_intrinsics,    ///< check_intrinsics failed, or they are for another image size
  output_too_small,  ///< out_capacity_points < width * height
};

const char* points_status_name(PointsStatus status) noexcept;

struct PointsResult {
  PointsStatus status = PointsStatus::ok;
  std::size_t valid_points = 0;  ///< pixels with a measurement (raw depth > 0)
};

/// Organised back-projection: point i = v * width + u occupies out_xyz[3 i .. 3 i + 2] (x, y, z,
/// metres, camera optical frame); pixels without a measurement (raw 0) get three quiet NaNs.
/// `depth` holds native-endian uint16 samples, row v starting at byte v * stride_bytes; it
/// need not be aligned. Nothing is written unless the status is ok.
PointsResult depth_to_points(const std::uint8_t* depth, std::size_t depth_bytes, int width, int height,
                             std::size_t stride_bytes, double depth_scale_m, const DepthIntrinsics& intrinsics,
                             double* out_xyz, std::size_t out_capacity_points) noexcept;
/// Same, single precision output.
PointsResult depth_to_points(const std::uint8_t* depth, std::size_t depth_bytes, int width, int height,
                             std::size_t stride_bytes, double depth_scale_m, const DepthIntrinsics& intrinsics,
                             float* out_xyz, std::size_t out_capacity_points) noexcept;

/// A HAL depth frame with its own intrinsics (NaN intrinsics: bad_intrinsics). The frame's
/// contract gives the buffer size: height * stride_bytes bytes.
PointsResult depth_to_points(const hal::DepthFrame& frame, double* out_xyz, std::size_t out_capacity_points) noexcept;

/// Copies a width x height depth image whose rows are stride_bytes apart (source size
/// src_bytes) into a packed destination of dst_capacity samples. False, nothing copied, when
/// the sizes do not fit (same rules as depth_to_points).
bool copy_depth_image(const std::uint8_t* src, std::size_t src_bytes, int width, int height, std::size_t stride_bytes,
                      std::uint16_t* dst, std::size_t dst_capacity) noexcept;

}  // namespace pliant::drivers::openni2
