// Depth images and the pinhole camera that took them.
//
// A depth image is a row-major grid of unsigned 16-bit raw depths along the optical axis; 0
// means "no measurement". One raw unit is `depth_scale_m` metres (1e-3 for millimetres, as
// OpenNI2, RealSense and Kinect drivers write; 1/5000 = 2e-4 for the TUM RGB-D benchmark).
//
// Camera (optical) frame, metres: x to the right of the image, y down, z forward along the
// optical axis. Pixel (u, v) is column u, row v; integer coordinates are pixel centres. With
// the pinhole intrinsics (fx, fy, cx, cy in pixels) a pixel with depth z back-projects to
//   X = ((u - cx) z / fx, (v - cy) z / fy, z)
// and a camera-frame point X with X.z > 0 projects to u = fx X.x / X.z + cx, v = fy X.y / X.z + cy.
//
// Host code: the readers allocate and throw DepthError with one line naming the input and the
// problem. The views are plain data (no ownership, no allocation).
#pragma once

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace pliant::hal {
struct DepthFrame;
}

namespace pliant::vision {

/// Every error of the depth front end: malformed image, intrinsics or options; one line.
class DepthError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Pinhole intrinsics of a depth image (no distortion: rectified or registered depth).
/// width and height are the image size the calibration is for; images of another size are
/// refused. A default-constructed value is "missing" and refused by check_intrinsics.
struct PinholeIntrinsics {
  double fx = 0;   ///< focal length along u, px, finite > 0
  double fy = 0;   ///< focal length along v, px, finite > 0
  double cx = 0;   ///< principal point column, px, finite
  double cy = 0;   ///< principal point row, px, finite
  int width = 0;   ///< image columns, >= 1
  int height = 0;  ///< image rows, >= 1
};

/// Throws DepthError naming the first bad field ("intrinsics: fx must be finite and > 0 (missing
/// intrinsics?)").
void check_intrinsics(const PinholeIntrinsics& intrinsics);

/// Non-owning view of a 16-bit depth image. Valid while the memory it points to is.
struct DepthImageView {
  const std::uint16_t* data = nullptr;  ///< row v starts at data + v * row_stride
  int width = 0;                        ///< columns
  int height = 0;                       ///< rows
  std::size_t row_stride = 0;           ///< elements between rows; 0 means width
  std::size_t stride() const noexcept { return row_stride == 0 ? static_cast<std::size_t>(width) : row_stride; }
  /// Raw depth at (u, v); the caller keeps 0 <= u < width, 0 <= v < height.
  std::uint16_t at(int u, int v) const noexcept {
    return data[static_cast<std::size_t>(v) * stride() + static_cast<std::size_t>(u)];
  }
};

/// An owned depth image (row-major, row_stride == width).
struct DepthImage {
  int width = 0;
  int height = 0;
  std::vector<std::uint16_t> data;  ///< width * height raw depths
  DepthImageView view() const noexcept { return {data.data(), width, height, static_cast<std::size_t>(width)}; }
};

/// Reads a single-channel 16-bit PNG (the TUM, OpenNI and RealSense export format; interlaced
/// or not), through libpng with its messages captured: nothing is printed. Throws DepthError
/// naming the file: missing or unreadable, empty, not a PNG, corrupt ("corrupt PNG (<libpng's
/// reason>)"; also a file too small to hold the image its header claims, refused before the
/// image is allocated), not 16-bit, not one grey channel, wider or taller than 16384 pixels.
/// Allocates the image.
DepthImage read_depth_png(const std::string& path);

/// The same from PNG bytes in memory; `label` names the input in errors. Used by the fuzz target.
DepthImage decode_depth_png(const std::uint8_t* bytes, std::size_t size, const std::string& label);

/// View of a HAL depth frame (no copy). Throws DepthError when the frame is malformed (null data,
/// non-positive size, stride_bytes not a whole number of pixels or smaller than a row).
DepthImageView depth_view(const hal::DepthFrame& frame);

/// Intrinsics a HAL depth frame reports (NaN fields become a DepthError: the device did not
/// report them; give them on the command line instead).
PinholeIntrinsics intrinsics_of(const hal::DepthFrame& frame);

}  // namespace pliant::vision
