// Command-line text of the depth front end: intrinsics, camera pose, pixel region.
//
// Each is a comma-separated list of decimal numbers (blanks around them allowed). Host code:
// throws DepthError naming the field and the problem ("intrinsics: cy is missing (expected
// fx,fy,cx,cy)").
#pragma once

#include <string_view>

#include <Eigen/Geometry>

#include "pliant/vision/depth_cloud.hpp"
#include "pliant/vision/depth_image.hpp"

namespace pliant::vision {

/// "fx,fy,cx,cy" (px) plus the image size the calibration is for. Refuses a wrong count, a
/// field that is not a number, trailing text, and values check_intrinsics refuses.
PinholeIntrinsics parse_intrinsics(std::string_view text, int width, int height);

/// "tx,ty,tz,qx,qy,qz,qw" (m, unit quaternion; the TUM benchmark's pose order): the camera's
/// pose in the world frame (x_world = R(q) x_camera + t). The quaternion is normalised; a norm
/// off 1 by more than 1e-3 (or zero) is refused as a likely typo.
Eigen::Isometry3d parse_camera_pose(std::string_view text);

/// "u0,v0,width,height" (px, integers >= 0, width and height >= 1).
PixelRect parse_pixel_rect(std::string_view text);

}  // namespace pliant::vision
