#include "pliant/vision/depth_text.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <string>

namespace pliant::vision {
namespace {

bool blank(char c) { return c == ' ' || c == '\t'; }

// A field for an error message: control bytes escaped, so the message stays one line.
std::string printable(std::string_view text) {
  static const char kHex[] = "0123456789abcdef";
  std::string out;
  for (const char c : text) {
    const auto byte = static_cast<unsigned char>(c);
    if (byte < 0x20 || byte == 0x7f) {
      out += "\\x";
      out += kHex[byte >> 4];
      out += kHex[byte & 0xf];
    } else {
      out += c;
    }
  }
  return out;
}

// `count` comma-separated decimal numbers named by `names` (for messages); `what` names the list.
template <std::size_t Count>
void parse_numbers(std::string_view text, const char* what, const char* const (&names)[Count], const char* expected,
                   double (&out)[Count]) {
  const std::string prefix = std::string(what) + ": ";
  const std::string tail = std::string(" (expected ") + expected + ")";
  for (std::size_t i = 0; i < Count; ++i) {
    if (i > 0) {
      if (text.empty() || text.front() != ',') throw DepthError(prefix + names[i] + " is missing" + tail);
      text.remove_prefix(1);
    }
    std::size_t end = 0;
    while (end < text.size() && text[end] != ',') ++end;
    std::string_view piece = text.substr(0, end);
    while (!piece.empty() && blank(piece.front())) piece.remove_prefix(1);
    while (!piece.empty() && blank(piece.back())) piece.remove_suffix(1);
    if (piece.empty()) throw DepthError(prefix + names[i] + " is missing" + tail);
    const std::string field(piece.substr(0, 40));
    char* stop = nullptr;
    errno = 0;
    out[i] = std::strtod(field.c_str(), &stop);
    // strtod would skip leading whitespace such as a line break: a field holds no control byte.
    const bool control = std::any_of(field.begin(), field.end(), [](char c) {
      const auto byte = static_cast<unsigned char>(c);
      return byte < 0x20 || byte == 0x7f;
    });
    if (piece.size() > 40 || control || stop != field.c_str() + field.size() || errno == ERANGE) {
      throw DepthError(prefix + names[i] + " is not a number: '" + printable(field) +
                       (piece.size() > 40 ? "...'" : "'"));
    }
    text.remove_prefix(end);
  }
  if (!text.empty()) throw DepthError(prefix + "trailing text after " + names[Count - 1] + tail);
}

}  // namespace

PinholeIntrinsics parse_intrinsics(std::string_view text, int width, int height) {
  static const char* const names[4] = {"fx", "fy", "cx", "cy"};
  double v[4] = {0, 0, 0, 0};
  parse_numbers(text, "intrinsics", names, "fx,fy,cx,cy", v);
  const PinholeIntrinsics k{v[0], v[1], v[2], v[3], width, height};
  check_intrinsics(k);
  return k;
}

Eigen::Isometry3d parse_camera_pose(std::string_view text) {
  static const char* const names[7] = {"tx", "ty", "tz", "qx", "qy", "qz", "qw"};
  double v[7] = {0, 0, 0, 0, 0, 0, 0};
  parse_numbers(text, "camera pose", names, "tx,ty,tz,qx,qy,qz,qw", v);
  for (const double x : v) {
    if (!std::isfinite(x)) throw DepthError("camera pose: every field must be finite");
  }
  Eigen::Quaterniond q(v[6], v[3], v[4], v[5]);
  if (std::abs(q.norm() - 1.0) > 1e-3) throw DepthError("camera pose: the quaternion must have norm 1");
  q.normalize();
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = q.toRotationMatrix();
  pose.translation() = Eigen::Vector3d(v[0], v[1], v[2]);
  return pose;
}

PixelRect parse_pixel_rect(std::string_view text) {
  static const char* const names[4] = {"u0", "v0", "width", "height"};
  double v[4] = {0, 0, 0, 0};
  parse_numbers(text, "region", names, "u0,v0,width,height", v);
  const double limit = static_cast<double>(std::numeric_limits<int>::max());
  for (int i = 0; i < 4; ++i) {
    if (!(v[i] >= 0 && v[i] <= limit) || std::floor(v[i]) != v[i]) {
      throw DepthError(std::string("region: ") + names[i] + " must be a whole number >= 0");
    }
  }
  if (v[2] < 1 || v[3] < 1) throw DepthError("region: width and height must be >= 1");
  return PixelRect{static_cast<int>(v[0]), static_cast<int>(v[1]), static_cast<int>(v[2]), static_cast<int>(v[3])};
}

}  // namespace pliant::vision
