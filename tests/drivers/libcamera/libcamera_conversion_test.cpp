// Native pixel formats into HAL frames: byte orders, YUV against a floating-point oracle and the
// standard colour-bar values, chroma siting, strides with padding, and every malformed geometry.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstdint>
#include <limits>
#include <vector>

#include "pixel_conversion.hpp"

namespace pliant::drivers::libcamera_detail {
namespace {

using hal::PixelFormat;

struct Rgb {
  int r, g, b;
};

// Y'CbCr to R'G'B' in doubles from the matrix definition (Kr, Kb), then rounded and clamped.
Rgb oracle_rgb(int y, int u, int v, YcbcrMatrix matrix, bool full_range) {
  const double kr = matrix == YcbcrMatrix::bt709 ? 0.2126 : 0.299;
  const double kb = matrix == YcbcrMatrix::bt709 ? 0.0722 : 0.114;
  const double kg = 1 - kr - kb;
  // Normalise: Y' in [0, 1], Cb, Cr in [-0.5, 0.5].
  const double yn = full_range ? y / 255.0 : (y - 16) / 219.0;
  const double cb = full_range ? (u - 128) / 255.0 : (u - 128) / 224.0;
  const double cr = full_range ? (v - 128) / 255.0 : (v - 128) / 224.0;
  const double r = yn + 2 * (1 - kr) * cr;
  const double b = yn + 2 * (1 - kb) * cb;
  const double g = (yn - kr * r - kb * b) / kg;
  const auto to8 = [](double x) { return static_cast<int>(std::lround(std::fmin(255.0, std::fmax(0.0, x * 255.0)))); };
  return {to8(r), to8(g), to8(b)};
}

int oracle_luma(int y, bool full_range) {
  const double yn = full_range ? y / 255.0 : (y - 16) / 219.0;
  return static_cast<int>(std::lround(std::fmin(255.0, std::fmax(0.0, yn * 255.0))));
}

RawImage packed(RawFormat format, int width, int height, const std::vector<std::uint8_t>& bytes, std::size_t stride) {
  RawImage image;
  image.format = format;
  image.width = width;
  image.height = height;
  image.plane[0] = bytes.data();
  image.plane_bytes[0] = bytes.size();
  image.stride[0] = stride;
  return image;
}

TEST(LibcameraConversion, FourccMapping) {
  EXPECT_EQ(raw_format_from_fourcc(fourcc('Y', 'U', 'Y', 'V')), RawFormat::yuyv);
  EXPECT_EQ(raw_format_from_fourcc(fourcc('R', 'G', '2', '4')), RawFormat::rgb888);
  EXPECT_EQ(raw_format_from_fourcc(fourcc('N', 'V', '2', '1')), RawFormat::nv21);
  EXPECT_EQ(raw_format_from_fourcc(fourcc('R', '8', ' ', ' ')), RawFormat::r8);
  EXPECT_EQ(raw_format_from_fourcc(fourcc('M', 'J', 'P', 'G')), RawFormat::unsupported);
  EXPECT_EQ(raw_format_from_fourcc(fourcc('B', 'A', '8', '1')), RawFormat::unsupported);  // Bayer
  EXPECT_EQ(raw_format_from_fourcc(0), RawFormat::unsupported);
  for (const RawFormat f : {RawFormat::rgb888, RawFormat::bgr888, RawFormat::xrgb8888, RawFormat::xbgr8888,
                            RawFormat::yuyv, RawFormat::uyvy, RawFormat::nv12, RawFormat::nv21, RawFormat::r8}) {
    EXPECT_EQ(raw_format_from_fourcc(raw_format_fourcc(f)), f) << raw_format_name(f);
  }
  EXPECT_STREQ(raw_format_name(RawFormat::xbgr8888), "XBGR8888");
  EXPECT_EQ(raw_format_planes(RawFormat::nv12), 2);
  EXPECT_EQ(raw_row_bytes(RawFormat::xrgb8888, 5), 20u);
}

TEST(LibcameraConversion, RgbByteOrders) {
  // One pixel R=200 G=100 B=50 in each layout (DRM names read backwards in memory).
  struct Case {
    RawFormat format;
    std::vector<std::uint8_t> bytes;
  };
  const Case cases[] = {
      {RawFormat::rgb888, {50, 100, 200}},
      {RawFormat::bgr888, {200, 100, 50}},
      {RawFormat::xrgb8888, {50, 100, 200, 7}},
      {RawFormat::xbgr8888, {200, 100, 50, 7}},
  };
  for (const Case& c : cases) {
    const RawImage image = packed(c.format, 1, 1, c.bytes, c.bytes.size());
    std::uint8_t out[3] = {};
    ASSERT_EQ(convert_raw(image, PixelFormat::rgb8, out, 3, 3), ConvertStatus::ok);
    EXPECT_EQ((std::vector<int>{out[0], out[1], out[2]}), (std::vector<int>{200, 100, 50}))
        << raw_format_name(c.format);
    ASSERT_EQ(convert_raw(image, PixelFormat::bgr8, out, 3, 3), ConvertStatus::ok);
    EXPECT_EQ((std::vector<int>{out[0], out[1], out[2]}), (std::vector<int>{50, 100, 200}))
        << raw_format_name(c.format);
    ASSERT_EQ(convert_raw(image, PixelFormat::mono8, out, 1, 1), ConvertStatus::ok);
    EXPECT_NEAR(out[0], 0.299 * 200 + 0.587 * 100 + 0.114 * 50, 1.0) << raw_format_name(c.format);
  }
  const std::vector<std::uint8_t> gray = {0, 77, 255};
  std::uint8_t out[9] = {};
  ASSERT_EQ(convert_raw(packed(RawFormat::r8, 3, 1, gray, 3), PixelFormat::rgb8, out, 9, 9), ConvertStatus::ok);
  EXPECT_EQ((std::vector<int>(out, out + 9)), (std::vector<int>{0, 0, 0, 77, 77, 77, 255, 255, 255}));
  ASSERT_EQ(convert_raw(packed(RawFormat::r8, 3, 1, gray, 3), PixelFormat::mono8, out, 3, 3), ConvertStatus::ok);
  EXPECT_EQ((std::vector<int>(out, out + 3)), (std::vector<int>{0, 77, 255}));
}

TEST(LibcameraConversion, YuvMatchesTheOracleWithinOne) {
  for (const YcbcrMatrix matrix : {YcbcrMatrix::bt601, YcbcrMatrix::bt709}) {
    for (const bool full : {false, true}) {
      int worst = 0, worst_luma = 0;
      for (int y = 0; y < 256; y += 3) {
        for (int u = 0; u < 256; u += 5) {
          for (int v = 0; v < 256; v += 7) {
            // One YUYV pair whose two pixels share (u, v).
            const std::vector<std::uint8_t> bytes = {static_cast<std::uint8_t>(y), static_cast<std::uint8_t>(u),
                                                     static_cast<std::uint8_t>(y), static_cast<std::uint8_t>(v)};
            RawImage image = packed(RawFormat::yuyv, 2, 1, bytes, 4);
            image.matrix = matrix;
            image.full_range = full;
            std::uint8_t out[6] = {};
            ASSERT_EQ(convert_raw(image, PixelFormat::rgb8, out, 6, 6), ConvertStatus::ok);
            const Rgb want = oracle_rgb(y, u, v, matrix, full);
            worst = std::max({worst, std::abs(out[0] - want.r), std::abs(out[1] - want.g), std::abs(out[2] - want.b)});
            ASSERT_EQ(convert_raw(image, PixelFormat::mono8, out, 2, 2), ConvertStatus::ok);
            worst_luma = std::max(worst_luma, std::abs(out[0] - oracle_luma(y, full)));
          }
        }
      }
      EXPECT_LE(worst, 1) << "matrix " << static_cast<int>(matrix) << " full " << full;
      EXPECT_LE(worst_luma, 1);
    }
  }
}

TEST(LibcameraConversion, StandardColourBars) {
  // BT.601 limited range: black, white and 100 % red, green, blue (ITU-R BT.601 code values).
  struct Bar {
    int y, u, v;
    Rgb rgb;
  };
  const Bar bars[] = {{16, 128, 128, {0, 0, 0}},
                      {235, 128, 128, {255, 255, 255}},
                      {81, 90, 240, {255, 0, 0}},
                      {145, 54, 34, {0, 255, 0}},
                      {41, 240, 110, {0, 0, 255}}};
  for (const Bar& bar : bars) {
    const std::vector<std::uint8_t> bytes = {static_cast<std::uint8_t>(bar.u), static_cast<std::uint8_t>(bar.y),
                                             static_cast<std::uint8_t>(bar.v), static_cast<std::uint8_t>(bar.y)};
    const RawImage image = packed(RawFormat::uyvy, 2, 1, bytes, 4);
    std::uint8_t out[6] = {};
    ASSERT_EQ(convert_raw(image, PixelFormat::rgb8, out, 6, 6), ConvertStatus::ok);
    EXPECT_NEAR(out[0], bar.rgb.r, 2) << "Y " << bar.y;
    EXPECT_NEAR(out[1], bar.rgb.g, 2) << "Y " << bar.y;
    EXPECT_NEAR(out[2], bar.rgb.b, 2) << "Y " << bar.y;
  }
}

// A 4x2 image: pixel (x, y) has luma 20 + 10 x + 100 y; chroma pair p of row r has
// U = 60 + 40 p + 70 r and V = 200 - 50 p - 60 r (for NV: row r is chroma row 0 for both rows).
int luma_at(int x, int y) { return 20 + 10 * x + 100 * y; }
int u_at(int pair, int row) { return 60 + 40 * pair + 70 * row; }
int v_at(int pair, int row) { return 200 - 50 * pair - 60 * row; }

void expect_pixels(const std::uint8_t* out, std::size_t stride, bool subsampled_rows, const char* what) {
  for (int y = 0; y < 2; ++y) {
    for (int x = 0; x < 4; ++x) {
      const int row = subsampled_rows ? 0 : y;
      const Rgb want = oracle_rgb(luma_at(x, y), u_at(x / 2, row), v_at(x / 2, row), YcbcrMatrix::bt601, false);
      const std::uint8_t* p = out + static_cast<std::size_t>(y) * stride + 3 * static_cast<std::size_t>(x);
      EXPECT_NEAR(p[0], want.r, 1) << what << " x " << x << " y " << y;
      EXPECT_NEAR(p[1], want.g, 1) << what << " x " << x << " y " << y;
      EXPECT_NEAR(p[2], want.b, 1) << what << " x " << x << " y " << y;
    }
  }
}

TEST(LibcameraConversion, ChromaSitingOfPackedAndSemiPlanarYuv) {
  const std::size_t stride = 12;  // 8 bytes of YUYV per row plus 4 of padding
  std::vector<std::uint8_t> yuyv(stride * 2, 0xEE), uyvy(stride * 2, 0xEE);
  for (int y = 0; y < 2; ++y) {
    for (int p = 0; p < 2; ++p) {
      std::uint8_t* a = yuyv.data() + static_cast<std::size_t>(y) * stride + 4 * static_cast<std::size_t>(p);
      a[0] = static_cast<std::uint8_t>(luma_at(2 * p, y));
      a[1] = static_cast<std::uint8_t>(u_at(p, y));
      a[2] = static_cast<std::uint8_t>(luma_at(2 * p + 1, y));
      a[3] = static_cast<std::uint8_t>(v_at(p, y));
      std::uint8_t* b = uyvy.data() + static_cast<std::size_t>(y) * stride + 4 * static_cast<std::size_t>(p);
      b[0] = a[1], b[1] = a[0], b[2] = a[3], b[3] = a[2];
    }
  }
  const std::size_t out_stride = 16;  // 12 bytes of RGB per row plus padding the converter leaves alone
  std::vector<std::uint8_t> out(out_stride * 2, 0);
  ASSERT_EQ(
      convert_raw(packed(RawFormat::yuyv, 4, 2, yuyv, stride), PixelFormat::rgb8, out.data(), out_stride, out.size()),
      ConvertStatus::ok);
  expect_pixels(out.data(), out_stride, false, "YUYV");
  EXPECT_EQ(out[12], 0);  // padding untouched
  ASSERT_EQ(
      convert_raw(packed(RawFormat::uyvy, 4, 2, uyvy, stride), PixelFormat::rgb8, out.data(), out_stride, out.size()),
      ConvertStatus::ok);
  expect_pixels(out.data(), out_stride, false, "UYVY");

  // NV12 / NV21: a Y plane (stride 6) and one chroma row for both luma rows.
  for (const RawFormat format : {RawFormat::nv12, RawFormat::nv21}) {
    std::vector<std::uint8_t> luma(12, 0xEE), chroma(6, 0xEE);
    for (int y = 0; y < 2; ++y)
      for (int x = 0; x < 4; ++x) luma[static_cast<std::size_t>(y * 6 + x)] = static_cast<std::uint8_t>(luma_at(x, y));
    for (int p = 0; p < 2; ++p) {
      const auto u = static_cast<std::uint8_t>(u_at(p, 0));
      const auto v = static_cast<std::uint8_t>(v_at(p, 0));
      chroma[static_cast<std::size_t>(2 * p)] = format == RawFormat::nv12 ? u : v;
      chroma[static_cast<std::size_t>(2 * p + 1)] = format == RawFormat::nv12 ? v : u;
    }
    RawImage image;
    image.format = format;
    image.width = 4;
    image.height = 2;
    image.plane[0] = luma.data();
    image.plane_bytes[0] = luma.size();
    image.stride[0] = 6;
    image.plane[1] = chroma.data();
    image.plane_bytes[1] = 4;  // exactly one chroma row of 4 bytes (no trailing padding needed)
    image.stride[1] = 6;
    ASSERT_EQ(convert_raw(image, PixelFormat::rgb8, out.data(), out_stride, out.size()), ConvertStatus::ok);
    expect_pixels(out.data(), out_stride, true, raw_format_name(format));
  }
}

TEST(LibcameraConversion, MalformedGeometryIsRefusedBeforeAnyAccess) {
  const std::vector<std::uint8_t> bytes(64, 1);
  std::vector<std::uint8_t> out(64, 0);
  const auto run = [&](RawImage image, PixelFormat format = PixelFormat::rgb8, std::size_t out_stride = 12,
                       std::size_t out_bytes = 64) {
    return convert_raw(image, format, out.data(), out_stride, out_bytes);
  };
  RawImage good = packed(RawFormat::yuyv, 4, 2, bytes, 8);
  ASSERT_EQ(run(good), ConvertStatus::ok);

  RawImage x = good;
  x.format = RawFormat::unsupported;
  EXPECT_EQ(run(x), ConvertStatus::unsupported_format);
  EXPECT_EQ(run(good, static_cast<PixelFormat>(9)), ConvertStatus::unsupported_format);
  x = good, x.width = 0;
  EXPECT_EQ(run(x), ConvertStatus::bad_geometry);
  x = good, x.height = -3;
  EXPECT_EQ(run(x), ConvertStatus::bad_geometry);
  x = good, x.width = 16386;
  EXPECT_EQ(run(x), ConvertStatus::bad_geometry);
  x = good, x.width = 3;  // YUYV needs pairs
  EXPECT_EQ(run(x), ConvertStatus::bad_geometry);
  x = good, x.stride[0] = 7;  // below one row
  EXPECT_EQ(run(x), ConvertStatus::bad_geometry);
  x = good, x.plane_bytes[0] = 15;  // one byte short of two rows
  EXPECT_EQ(run(x), ConvertStatus::short_buffer);
  x = good, x.plane[0] = nullptr;
  EXPECT_EQ(run(x), ConvertStatus::short_buffer);
  x = good, x.stride[0] = std::numeric_limits<std::size_t>::max() / 2;  // stride x rows overflows
  x.height = 3;
  EXPECT_EQ(run(x), ConvertStatus::short_buffer);
  EXPECT_EQ(run(good, PixelFormat::rgb8, 11), ConvertStatus::output_too_small);
  EXPECT_EQ(run(good, PixelFormat::rgb8, 12, 23), ConvertStatus::output_too_small);
  EXPECT_EQ(convert_raw(good, PixelFormat::rgb8, nullptr, 12, 64), ConvertStatus::output_too_small);
  EXPECT_EQ(run(good, PixelFormat::mono8, 4, 8), ConvertStatus::ok);

  RawImage nv;
  nv.format = RawFormat::nv12;
  nv.width = 4;
  nv.height = 2;
  nv.plane[0] = bytes.data();
  nv.plane_bytes[0] = 8;
  nv.stride[0] = 4;
  nv.plane[1] = bytes.data() + 8;
  nv.plane_bytes[1] = 4;
  nv.stride[1] = 4;
  ASSERT_EQ(run(nv), ConvertStatus::ok);
  x = nv, x.height = 3;
  EXPECT_EQ(run(x), ConvertStatus::bad_geometry);
  x = nv, x.plane[1] = nullptr;
  EXPECT_EQ(run(x), ConvertStatus::short_buffer);
  x = nv, x.plane_bytes[1] = 3;
  EXPECT_EQ(run(x), ConvertStatus::short_buffer);
  x = nv, x.stride[1] = 2;
  EXPECT_EQ(run(x), ConvertStatus::bad_geometry);
  EXPECT_STREQ(convert_status_name(ConvertStatus::short_buffer), "short_buffer");
}

}  // namespace
}  // namespace pliant::drivers::libcamera_detail
