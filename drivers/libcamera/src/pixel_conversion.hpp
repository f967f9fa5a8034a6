// drivers/libcamera internal: the camera's native pixel formats and their conversion into HAL
// frames. Pure code (no libcamera): the fourcc codes are DRM's, as libcamera uses them.
//
// Byte order in memory (DRM names are little-endian words, so they read backwards):
//   RGB888 B,G,R   BGR888 R,G,B   XRGB8888 B,G,R,x   XBGR8888 R,G,B,x   R8 gray
//   YUYV Y0,U,Y1,V   UYVY U,Y0,V,Y1 (one U,V pair per two pixels of a row)
//   NV12 a Y plane, then a plane of U,V pairs at half resolution in both directions; NV21 V,U.
#pragma once

#include <cstddef>
#include <cstdint>

#include "pliant/hal/camera.hpp"

namespace pliant::drivers::libcamera_detail {

enum class RawFormat : std::uint8_t { rgb888, bgr888, xrgb8888, xbgr8888, yuyv, uyvy, nv12, nv21, r8, unsupported };

/// A fourcc code from its four characters.
constexpr std::uint32_t fourcc(char a, char b, char c, char d) noexcept {
  return static_cast<std::uint32_t>(static_cast<unsigned char>(a)) |
         static_cast<std::uint32_t>(static_cast<unsigned char>(b)) << 8 |
         static_cast<std::uint32_t>(static_cast<unsigned char>(c)) << 16 |
         static_cast<std::uint32_t>(static_cast<unsigned char>(d)) << 24;
}

/// The format of a DRM fourcc (libcamera::PixelFormat::fourcc() with modifier 0); unsupported
/// for every other code (MJPEG, Bayer, planar 4:2:0, ...).
RawFormat raw_format_from_fourcc(std::uint32_t code) noexcept;
/// Its fourcc (0 for unsupported).
std::uint32_t raw_format_fourcc(RawFormat format) noexcept;
/// Short name ("YUYV", "RGB888", ...; "unsupported").
const char* raw_format_name(RawFormat format) noexcept;
/// Planes of a format (1, or 2 for NV12/NV21).
int raw_format_planes(RawFormat format) noexcept;
/// Bytes of one row of plane 0 for `width` pixels (the minimum stride).
std::size_t raw_row_bytes(RawFormat format, int width) noexcept;

enum class YcbcrMatrix : std::uint8_t { bt601, bt709 };

/// One native image: plane pointers with their byte counts and strides (for a single-plane
/// NV12/NV21 buffer, plane 1 is the part of plane 0 after stride * height bytes).
struct RawImage {
  RawFormat format = RawFormat::unsupported;
  int width = 0;
  int height = 0;
  const std::uint8_t* plane[2] = {nullptr, nullptr};
  std::size_t plane_bytes[2] = {0, 0};  ///< bytes readable from plane[i]
  std::size_t stride[2] = {0, 0};       ///< bytes from one row to the next, per plane
  YcbcrMatrix matrix = YcbcrMatrix::bt601;
  bool full_range = false;  ///< YUV: 0..255 (true) or 16..235 / 16..240 (false)
};

enum class ConvertStatus : std::uint8_t {
  ok,
  unsupported_format,  ///< not a format this file converts, or an unknown output format
  bad_geometry,        ///< size outside 1..16384, odd width (YUYV/UYVY/NV), odd height (NV), a stride below a row
  short_buffer,        ///< a plane holds fewer bytes than its rows need
  output_too_small,    ///< out_stride below a row of the output, or out_bytes below the frame
};

const char* convert_status_name(ConvertStatus status) noexcept;

/// Converts `in` into `out_format` at `out` (rows out_stride bytes apart, out_bytes in all).
/// Checks every size against the buffers before reading or writing (outside input: the
/// camera's buffer and libcamera's bytes-used). O(width x height), allocation-free, noexcept.
/// YUV to RGB: integer arithmetic, within 1 of the exact matrix rounded; to mono8: the luma
/// (expanded to 0..255 for limited range). RGB to mono8: BT.601 luma weights.
ConvertStatus convert_raw(const RawImage& in, hal::PixelFormat out_format, std::uint8_t* out, std::size_t out_stride,
                          std::size_t out_bytes) noexcept;

}  // namespace pliant::drivers::libcamera_detail
