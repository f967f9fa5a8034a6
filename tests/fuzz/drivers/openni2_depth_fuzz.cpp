// libFuzzer target: depth frames as drivers/openni2 sees them. The first 40 bytes choose the
// layout (width, height, stride, depth scale, intrinsics: possibly absurd, NaN, negative); the
// rest is the frame buffer, handed to copy_depth_image and to depth_to_points (double and
// float). Checks: no crash or sanitizer error, both conversions agree on the status and on
// which pixels are valid, valid points have z > 0 and finite coordinates, and a refused call
// writes nothing.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "pliant/drivers/openni2/depth_points.hpp"

namespace {

template <typename T>
T take(const std::uint8_t*& data, std::size_t& size) {
  T value{};
  if (size >= sizeof value) {
    std::memcpy(&value, data, sizeof value);
    data += sizeof value;
    size -= sizeof value;
  }
  return value;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace pliant::drivers::openni2;
  // Small sizes keep every run fast; the sign and the range checks still see the raw values.
  const int width = static_cast<int>(take<std::int16_t>(data, size)) % 97;
  const int height = static_cast<int>(take<std::int16_t>(data, size)) % 97;
  const std::size_t stride = take<std::uint16_t>(data, size) % 512;
  const double scale = static_cast<double>(take<float>(data, size));
  DepthIntrinsics k;
  k.fx = static_cast<double>(take<float>(data, size));
  k.fy = static_cast<double>(take<float>(data, size));
  k.cx = static_cast<double>(take<float>(data, size));
  k.cy = static_cast<double>(take<float>(data, size));
  const std::uint8_t same_size = take<std::uint8_t>(data, size);
  k.width = (same_size & 1) != 0 ? width : static_cast<int>(take<std::int16_t>(data, size));
  k.height = (same_size & 2) != 0 ? height : static_cast<int>(take<std::int16_t>(data, size));
  const double hfov = static_cast<double>(take<float>(data, size));
  const double vfov = static_cast<double>(take<float>(data, size));

  DepthIntrinsics from_fov;
  if (intrinsics_from_fov(hfov, vfov, width, height, from_fov) == IntrinsicsCheck::ok) {
    if (check_intrinsics(from_fov) != IntrinsicsCheck::ok) std::abort();
  }

  const std::size_t pixels =
      width > 0 && height > 0 ? static_cast<std::size_t>(width) * static_cast<std::size_t>(height) : 0;
  const std::size_t capacity = pixels > 0 ? pixels - (same_size >> 7) : 0;  // sometimes one short
  std::vector<std::uint16_t> packed(capacity + 1, 0xABCD);
  const bool copied = copy_depth_image(data, size, width, height, stride, packed.data(), capacity);
  if (!copied) {
    for (std::uint16_t v : packed) {
      if (v != 0xABCD) std::abort();
    }
  }

  std::vector<double> xyz(3 * capacity + 3, 42.0);
  std::vector<float> xyz_f(3 * capacity + 3, 42.0f);
  const PointsResult r = depth_to_points(data, size, width, height, stride, scale, k, xyz.data(), capacity);
  const PointsResult r_f = depth_to_points(data, size, width, height, stride, scale, k, xyz_f.data(), capacity);
  if (r.status != r_f.status || r.valid_points != r_f.valid_points) std::abort();
  if (r.status != PointsStatus::ok) {
    for (double v : xyz) {
      if (v != 42.0) std::abort();
    }
    return 0;
  }
  if (!copied) std::abort();  // the same layout rules
  std::size_t valid = 0;
  for (std::size_t i = 0; i < pixels; ++i) {
    const double* p = &xyz[3 * i];
    const bool has = packed[i] != 0;
    if (has != !std::isnan(p[2]) || has != !std::isnan(xyz_f[3 * i + 2])) std::abort();
    if (!has) continue;
    ++valid;
    if (!(p[2] > 0) || !std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2])) std::abort();
  }
  if (valid != r.valid_points || xyz[3 * pixels] != 42.0) std::abort();
  return 0;
}
