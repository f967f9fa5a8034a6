// Region parsing and grid seeding.
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "pliant/vision/webcam_error.hpp"
#include "pliant/vision/webcam_grid.hpp"

namespace pliant::vision::webcam {
namespace {

// Parses a decimal integer in [lo, hi] occupying the whole of `text`.
bool parse_int(const std::string& text, long lo, long hi, long& out) {
  if (text.empty() || text.size() > 12) return false;
  char* end = nullptr;
  errno = 0;
  const long value = std::strtol(text.c_str(), &end, 10);
  if (errno != 0 || end != text.c_str() + text.size() || value < lo || value > hi) return false;
  out = value;
  return true;
}

std::vector<std::string> split(const std::string& text, char separator) {
  std::vector<std::string> parts;
  std::size_t start = 0;
  for (;;) {
    const std::size_t at = text.find(separator, start);
    parts.push_back(text.substr(start, at == std::string::npos ? std::string::npos : at - start));
    if (at == std::string::npos) return parts;
    start = at + 1;
  }
}

std::string size_text(const cv::Size& size) { return std::to_string(size.width) + "x" + std::to_string(size.height); }

constexpr int kMaxGridSide = 1000;
constexpr int kMinParticles = 3;

}  // namespace

Region parse_roi(const std::string& text) {
  const std::vector<std::string> parts = split(text, ',');
  long v[4] = {0, 0, 0, 0};
  bool ok = parts.size() == 4;
  for (std::size_t i = 0; ok && i < 4; ++i) ok = parse_int(parts[i], i < 2 ? -1000000 : 0, 1000000, v[i]);
  if (!ok) throw InputError("--roi: expected x,y,w,h in pixels (integers, w and h >= 0), found '" + text + "'");
  Region region;
  region.roi = cv::Rect(static_cast<int>(v[0]), static_cast<int>(v[1]), static_cast<int>(v[2]), static_cast<int>(v[3]));
  region.label = "--roi " + text;
  return region;
}

Region read_mask(const std::string& path) {
  Region region;
  region.label = path;
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error)) throw InputError(path + ": no such file");
  try {
    region.mask = cv::imread(path, cv::IMREAD_GRAYSCALE);
  } catch (const cv::Exception&) {
    region.mask.release();
  }
  if (region.mask.empty()) throw InputError(path + ": cannot read the mask image (missing, damaged or not an image)");
  return region;
}

GridSpec parse_grid(const std::string& text) {
  std::string lower = text;
  for (char& c : lower) c = c == 'X' ? 'x' : c;
  const std::vector<std::string> parts = split(lower, 'x');
  long rows = 0, cols = 0;
  if (parts.size() != 2 || !parse_int(parts[0], 1, kMaxGridSide, rows) || !parse_int(parts[1], 1, kMaxGridSide, cols)) {
    throw InputError("--grid: expected ROWSxCOLS (e.g. 4x8, each 1.." + std::to_string(kMaxGridSide) + "), found '" +
                     text + "'");
  }
  GridSpec spec;
  spec.rows = static_cast<int>(rows);
  spec.cols = static_cast<int>(cols);
  return spec;
}

ParticleGrid seed_particles(const Region& region, const GridSpec& spec, const cv::Size& frame_size) {
  const cv::Rect frame(0, 0, frame_size.width, frame_size.height);
  cv::Rect box = region.roi;
  if (!region.mask.empty()) {
    if (region.mask.size() != frame_size) {
      throw InputError(region.label + ": mask is " + size_text(region.mask.size()) + ", the frames are " +
                       size_text(frame_size));
    }
    if (region.mask.type() != CV_8UC1) throw InputError(region.label + ": mask must be an 8-bit grey image");
    const int inside = cv::countNonZero(region.mask);
    if (inside == 0) throw InputError(region.label + ": empty region (no pixel of the mask is set)");
    box = cv::boundingRect(region.mask);
  } else {
    if (box.width <= 0 || box.height <= 0) throw InputError(region.label + ": empty region (zero width or height)");
    if ((box & frame) != box) {
      throw InputError(region.label + ": the region reaches outside the " + size_text(frame_size) + " frame");
    }
  }
  if (spec.rows < 0 || spec.cols < 0 || spec.rows > kMaxGridSide || spec.cols > kMaxGridSide ||
      (spec.rows == 0) != (spec.cols == 0)) {
    throw InputError("--grid: rows and columns must both be given, 1.." + std::to_string(kMaxGridSide));
  }
  if (!(std::isfinite(spec.spacing_px) && spec.spacing_px >= 0))
    throw InputError("--spacing must be a finite number of pixels");
  if (spec.spacing_px > 0 && spec.spacing_px < 2) throw InputError("--spacing must be at least 2 px");
  if (spec.rows == 0 && spec.spacing_px == 0) throw InputError("give --grid, --spacing or both");

  // Continuous extent of the box: [x - 1/2, x + w - 1/2] (pixel centres at integers).
  const double left = box.x - 0.5, top = box.y - 0.5;
  ParticleGrid grid;
  double step_x = 0, step_y = 0, origin_x = 0, origin_y = 0;
  if (spec.spacing_px == 0) {
    grid.rows = spec.rows;
    grid.cols = spec.cols;
    step_x = static_cast<double>(box.width) / spec.cols;
    step_y = static_cast<double>(box.height) / spec.rows;
  } else {
    step_x = step_y = spec.spacing_px;
    if (spec.rows > 0) {
      grid.rows = spec.rows;
      grid.cols = spec.cols;
      if (spec.cols * spec.spacing_px > box.width + 1e-9 || spec.rows * spec.spacing_px > box.height + 1e-9) {
        throw InputError(std::to_string(spec.rows) + "x" + std::to_string(spec.cols) + " particles " +
                         std::to_string(static_cast<long>(std::lround(spec.spacing_px))) +
                         " px apart do not fit in the " + size_text(box.size()) + " region of " + region.label);
      }
    } else {
      grid.cols = static_cast<int>(std::min<double>(kMaxGridSide, std::floor(box.width / spec.spacing_px)));
      grid.rows = static_cast<int>(std::min<double>(kMaxGridSide, std::floor(box.height / spec.spacing_px)));
    }
  }
  origin_x = left + 0.5 * (box.width - grid.cols * step_x) + 0.5 * step_x;
  origin_y = top + 0.5 * (box.height - grid.rows * step_y) + 0.5 * step_y;
  grid.spacing_x_px = step_x;
  grid.spacing_y_px = step_y;
  for (int r = 0; r < grid.rows; ++r) {
    for (int c = 0; c < grid.cols; ++c) {
      const cv::Point2d p(origin_x + c * step_x, origin_y + r * step_y);
      if (!region.mask.empty()) {
        const int px = static_cast<int>(std::lround(p.x)), py = static_cast<int>(std::lround(p.y));
        if (!frame.contains(cv::Point(px, py)) || region.mask.at<std::uint8_t>(py, px) == 0) continue;
      }
      grid.positions.push_back(p);
      grid.row.push_back(r);
      grid.col.push_back(c);
    }
  }
  if (grid.size() < kMinParticles) {
    throw InputError(region.label + ": " + std::to_string(grid.size()) + " particle(s) in the region, at least " +
                     std::to_string(kMinParticles) + " are needed (a larger region or a finer grid)");
  }
  return grid;
}

}  // namespace pliant::vision::webcam
