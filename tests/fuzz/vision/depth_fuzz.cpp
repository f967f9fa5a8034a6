// libFuzzer target over the depth front end's readers (host/vision/depth): the 16-bit PNG decoder
// (then the decoded image through the point-cloud conversion), the TUM-style frame list, and the
// command-line texts (intrinsics, camera pose, region).
//
// The first byte picks the reader; the rest is its input. Every input must end in a result or a
// DepthError with a one-line message, without a crash, a sanitizer report or a leak. Results are
// checked: a decoded image has width x height samples, its cloud only finite points with z > 0
// that project back to their pixel; a list has strictly increasing finite times; a pose is rigid.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <string_view>

#include "pliant/vision/depth_cloud.hpp"
#include "pliant/vision/depth_image.hpp"
#include "pliant/vision/depth_list.hpp"
#include "pliant/vision/depth_text.hpp"

namespace {

using namespace pliant::vision;

void check(bool condition) {
  if (!condition) std::abort();
}

void one_line(const DepthError& error) {
  const std::string message = error.what();
  check(!message.empty() && message.find('\n') == std::string::npos);
}

void png(const std::uint8_t* data, std::size_t size) {
  DepthImage image;
  try {
    image = decode_depth_png(data, size, "fuzz.png");
  } catch (const DepthError& error) {
    one_line(error);
    return;
  }
  check(image.width >= 1 && image.height >= 1);
  check(image.data.size() == static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height));
  const PinholeIntrinsics k{500.0, 500.0, 0.5 * image.width, 0.5 * image.height, image.width, image.height};
  DepthToCloudOptions options;
  options.stride = 1 + static_cast<int>(size % 3);
  DepthCloud cloud;
  try {
    depth_to_cloud(image.view(), k, options, cloud);
  } catch (const DepthError& error) {
    one_line(error);
    return;
  }
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Eigen::Vector3f& p = cloud.points[i];
    check(p.allFinite() && p.z() > 0);
    const double u = k.fx * static_cast<double>(p.x()) / static_cast<double>(p.z()) + k.cx;
    check(std::abs(u - cloud.pixel[i] % image.width) < 1e-2);
  }
}

void list(std::string_view text) {
  try {
    const std::vector<DepthListEntry> entries = parse_depth_list(text, "depth.txt");
    check(!entries.empty());
    for (std::size_t i = 0; i < entries.size(); ++i) {
      check(std::isfinite(entries[i].t_s) && !entries[i].path.empty());
      if (i > 0) check(entries[i].t_s > entries[i - 1].t_s);
      // depth_frames.csv rows carry a positive scale, TUM rows none; intrinsics number or NaN.
      const DepthListEntry& e = entries[i];
      check(std::isnan(e.depth_scale_m) == std::isnan(entries[0].depth_scale_m));
      check(std::isnan(e.depth_scale_m) || (std::isfinite(e.depth_scale_m) && e.depth_scale_m > 0));
      check(!std::isinf(e.fx) && !std::isinf(e.fy) && !std::isinf(e.cx) && !std::isinf(e.cy));
    }
  } catch (const DepthError& error) {
    one_line(error);
  }
}

void texts(std::uint8_t which, std::string_view text) {
  try {
    if (which == 2) {
      const PinholeIntrinsics k = parse_intrinsics(text, 640, 480);
      check(k.fx > 0 && k.fy > 0 && std::isfinite(k.cx) && std::isfinite(k.cy));
    } else if (which == 3) {
      const Eigen::Isometry3d pose = parse_camera_pose(text);
      const Eigen::Matrix3d r = pose.linear();
      check((r.transpose() * r - Eigen::Matrix3d::Identity()).norm() < 1e-9 && pose.translation().allFinite());
    } else {
      const PixelRect r = parse_pixel_rect(text);
      check(r.u0 >= 0 && r.v0 >= 0 && r.width >= 1 && r.height >= 1);
    }
  } catch (const DepthError& error) {
    one_line(error);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::uint8_t which = data[0] % 5;
  const std::uint8_t* rest = data + 1;
  const std::size_t length = size - 1;
  const std::string_view text(reinterpret_cast<const char*>(rest), length);
  if (which == 0) {
    png(rest, length);
  } else if (which == 1) {
    list(text);
  } else {
    texts(which, text);
  }
  return 0;
}
