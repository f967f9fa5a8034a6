#include "pixel_conversion.hpp"

namespace pliant::drivers::libcamera_detail {

namespace {

constexpr int kMaxSide = 16384;
constexpr int kShift = 16;
constexpr std::int32_t kHalf = 1 << (kShift - 1);

std::uint8_t clamp_shift(std::int32_t value) noexcept {
  if (value <= 0) return 0;
  const std::int32_t shifted = value >> kShift;
  return static_cast<std::uint8_t>(shifted > 255 ? 255 : shifted);
}

std::int32_t fixed(double value) noexcept {
  const double scaled = value * (1 << kShift);
  return static_cast<std::int32_t>(scaled < 0 ? scaled - 0.5 : scaled + 0.5);
}

// Y'CbCr to R'G'B' in 16.16 fixed point: R = y*(Y-yo) + rv*(V-128), G = y*(Y-yo) - gu*(U-128)
// - gv*(V-128), B = y*(Y-yo) + bu*(U-128).
struct YuvCoefficients {
  std::int32_t y_offset, y, rv, gu, gv, bu;
};

YuvCoefficients yuv_coefficients(YcbcrMatrix matrix, bool full_range) noexcept {
  const double kr = matrix == YcbcrMatrix::bt709 ? 0.2126 : 0.299;
  const double kb = matrix == YcbcrMatrix::bt709 ? 0.0722 : 0.114;
  const double kg = 1.0 - kr - kb;
  const double y_scale = full_range ? 1.0 : 255.0 / 219.0;
  const double c_scale = full_range ? 1.0 : 255.0 / 224.0;
  YuvCoefficients c{};
  c.y_offset = full_range ? 0 : 16;
  c.y = fixed(y_scale);
  c.rv = fixed(c_scale * 2.0 * (1.0 - kr));
  c.gu = fixed(c_scale * 2.0 * kb * (1.0 - kb) / kg);
  c.gv = fixed(c_scale * 2.0 * kr * (1.0 - kr) / kg);
  c.bu = fixed(c_scale * 2.0 * (1.0 - kb));
  return c;
}

// Writes one pixel in the output format; returns the next output position.
std::uint8_t* put(std::uint8_t* o, hal::PixelFormat format, std::uint8_t r, std::uint8_t g, std::uint8_t b) noexcept {
  switch (format) {
    case hal::PixelFormat::rgb8: o[0] = r, o[1] = g, o[2] = b; return o + 3;
    case hal::PixelFormat::bgr8: o[0] = b, o[1] = g, o[2] = r; return o + 3;
    case hal::PixelFormat::mono8: {
      // BT.601 luma weights, 16.16 (they sum to 65536).
      const std::int32_t luma = 19595 * r + 38470 * g + 7471 * b + kHalf;
      o[0] = clamp_shift(luma);
      return o + 1;
    }
  }
  return o;
}

std::uint8_t* put_yuv(std::uint8_t* o, hal::PixelFormat format, const YuvCoefficients& c, int y, int u,
                      int v) noexcept {
  const std::int32_t luma = c.y * (y - c.y_offset);
  if (format == hal::PixelFormat::mono8) {
    o[0] = clamp_shift(luma + kHalf);
    return o + 1;
  }
  const int du = u - 128, dv = v - 128;
  const std::uint8_t r = clamp_shift(luma + c.rv * dv + kHalf);
  const std::uint8_t g = clamp_shift(luma - c.gu * du - c.gv * dv + kHalf);
  const std::uint8_t b = clamp_shift(luma + c.bu * du + kHalf);
  if (format == hal::PixelFormat::rgb8) {
    o[0] = r, o[1] = g, o[2] = b;
  } else {
    o[0] = b, o[1] = g, o[2] = r;
  }
  return o + 3;
}

// True when `bytes` hold `rows` rows of `row` bytes each `stride` apart (no overflow).
bool fits(std::size_t bytes, std::size_t stride, std::size_t rows, std::size_t row) noexcept {
  if (rows == 0) return true;
  if (bytes < row) return false;
  if (rows == 1) return true;
  return stride != 0 && rows - 1 <= (bytes - row) / stride;
}

bool valid_output(hal::PixelFormat format) noexcept {
  return format == hal::PixelFormat::rgb8 || format == hal::PixelFormat::bgr8 || format == hal::PixelFormat::mono8;
}

}  // namespace

RawFormat raw_format_from_fourcc(std::uint32_t code) noexcept {
  constexpr RawFormat all[] = {RawFormat::rgb888,   RawFormat::bgr888, RawFormat::xrgb8888,
                               RawFormat::xbgr8888, RawFormat::yuyv,   RawFormat::uyvy,
                               RawFormat::nv12,     RawFormat::nv21,   RawFormat::r8};
  for (const RawFormat format : all) {
    if (raw_format_fourcc(format) == code) return format;
  }
  return RawFormat::unsupported;
}

std::uint32_t raw_format_fourcc(RawFormat format) noexcept {
  switch (format) {
    case RawFormat::rgb888: return fourcc('R', 'G', '2', '4');
    case RawFormat::bgr888: return fourcc('B', 'G', '2', '4');
    case RawFormat::xrgb8888: return fourcc('X', 'R', '2', '4');
    case RawFormat::xbgr8888: return fourcc('X', 'B', '2', '4');
    case RawFormat::yuyv: return fourcc('Y', 'U', 'Y', 'V');
    case RawFormat::uyvy: return fourcc('U', 'Y', 'V', 'Y');
    case RawFormat::nv12: return fourcc('N', 'V', '1', '2');
    case RawFormat::nv21: return fourcc('N', 'V', '2', '1');
    case RawFormat::r8: return fourcc('R', '8', ' ', ' ');
    case RawFormat::unsupported: break;
  }
  return 0;
}

const char* raw_format_name(RawFormat format) noexcept {
  switch (format) {
    case RawFormat::rgb888: return "RGB888";
    case RawFormat::bgr888: return "BGR888";
    case RawFormat::xrgb8888: return "XRGB8888";
    case RawFormat::xbgr8888: return "XBGR8888";
    case RawFormat::yuyv: return "YUYV";
    case RawFormat::uyvy: return "UYVY";
    case RawFormat::nv12: return "NV12";
    case RawFormat::nv21: return "NV21";
    case RawFormat::r8: return "R8";
    case RawFormat::unsupported: break;
  }
  return "unsupported";
}

int raw_format_planes(RawFormat format) noexcept {
  return (format == RawFormat::nv12 || format == RawFormat::nv21) ? 2 : 1;
}

std::size_t raw_row_bytes(RawFormat format, int width) noexcept {
  const auto w = static_cast<std::size_t>(width > 0 ? width : 0);
  switch (format) {
    case RawFormat::rgb888:
    case RawFormat::bgr888: return 3 * w;
    case RawFormat::xrgb8888:
    case RawFormat::xbgr8888: return 4 * w;
    case RawFormat::yuyv:
    case RawFormat::uyvy: return 2 * w;
    case RawFormat::nv12:
    case RawFormat::nv21:
    case RawFormat::r8: return w;
    case RawFormat::unsupported: break;
  }
  return 0;
}

const char* convert_status_name(ConvertStatus status) noexcept {
  switch (status) {
    case ConvertStatus::ok: return "ok";
    case ConvertStatus::unsupported_format: return "unsupported_format";
    case ConvertStatus::bad_geometry: return "bad_geometry";
    case ConvertStatus::short_buffer: return "short_buffer";
    case ConvertStatus::output_too_small: return "output_too_small";
  }
  return "unknown";
}

ConvertStatus convert_raw(const RawImage& in, hal::PixelFormat out_format, std::uint8_t* out, std::size_t out_stride,
                          std::size_t out_bytes) noexcept {
  if (in.format == RawFormat::unsupported || !valid_output(out_format)) return ConvertStatus::unsupported_format;
  const int w = in.width, h = in.height;
  if (w < 1 || h < 1 || w > kMaxSide || h > kMaxSide) return ConvertStatus::bad_geometry;
  const bool packed_yuv = in.format == RawFormat::yuyv || in.format == RawFormat::uyvy;
  const bool semi_planar = in.format == RawFormat::nv12 || in.format == RawFormat::nv21;
  if ((packed_yuv || semi_planar) && w % 2 != 0) return ConvertStatus::bad_geometry;
  if (semi_planar && h % 2 != 0) return ConvertStatus::bad_geometry;
  const std::size_t row = raw_row_bytes(in.format, w);
  const auto rows = static_cast<std::size_t>(h);
  if (in.stride[0] < row) return ConvertStatus::bad_geometry;
  if (in.plane[0] == nullptr || !fits(in.plane_bytes[0], in.stride[0], rows, row)) return ConvertStatus::short_buffer;
  if (semi_planar) {
    if (in.stride[1] < row) return ConvertStatus::bad_geometry;
    if (in.plane[1] == nullptr || !fits(in.plane_bytes[1], in.stride[1], rows / 2, row))
      return ConvertStatus::short_buffer;
  }
  const std::size_t out_row = static_cast<std::size_t>(w) * static_cast<std::size_t>(hal::pixel_bytes(out_format));
  if (out == nullptr || out_stride < out_row || !fits(out_bytes, out_stride, rows, out_row)) {
    return ConvertStatus::output_too_small;
  }

  const YuvCoefficients c = yuv_coefficients(in.matrix, in.full_range);
  for (int y = 0; y < h; ++y) {
    const std::uint8_t* s = in.plane[0] + static_cast<std::size_t>(y) * in.stride[0];
    std::uint8_t* o = out + static_cast<std::size_t>(y) * out_stride;
    switch (in.format) {
      case RawFormat::rgb888:  // B,G,R
        for (int x = 0; x < w; ++x, s += 3) o = put(o, out_format, s[2], s[1], s[0]);
        break;
      case RawFormat::bgr888:  // R,G,B
        for (int x = 0; x < w; ++x, s += 3) o = put(o, out_format, s[0], s[1], s[2]);
        break;
      case RawFormat::xrgb8888:  // B,G,R,x
        for (int x = 0; x < w; ++x, s += 4) o = put(o, out_format, s[2], s[1], s[0]);
        break;
      case RawFormat::xbgr8888:  // R,G,B,x
        for (int x = 0; x < w; ++x, s += 4) o = put(o, out_format, s[0], s[1], s[2]);
        break;
      case RawFormat::r8:
        for (int x = 0; x < w; ++x, ++s) o = put(o, out_format, s[0], s[0], s[0]);
        break;
      case RawFormat::yuyv:  // Y0,U,Y1,V
        for (int x = 0; x < w; x += 2, s += 4) {
          o = put_yuv(o, out_format, c, s[0], s[1], s[3]);
          o = put_yuv(o, out_format, c, s[2], s[1], s[3]);
        }
        break;
      case RawFormat::uyvy:  // U,Y0,V,Y1
        for (int x = 0; x < w; x += 2, s += 4) {
          o = put_yuv(o, out_format, c, s[1], s[0], s[2]);
          o = put_yuv(o, out_format, c, s[3], s[0], s[2]);
        }
        break;
      case RawFormat::nv12:
      case RawFormat::nv21: {
        const std::uint8_t* uv = in.plane[1] + static_cast<std::size_t>(y / 2) * in.stride[1];
        const int iu = in.format == RawFormat::nv12 ? 0 : 1;
        for (int x = 0; x < w; x += 2, s += 2, uv += 2) {
          o = put_yuv(o, out_format, c, s[0], uv[iu], uv[1 - iu]);
          o = put_yuv(o, out_format, c, s[1], uv[iu], uv[1 - iu]);
        }
        break;
      }
      case RawFormat::unsupported: return ConvertStatus::unsupported_format;
    }
  }
  return ConvertStatus::ok;
}

}  // namespace pliant::drivers::libcamera_detail
