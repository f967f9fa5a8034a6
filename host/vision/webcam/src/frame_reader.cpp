// Resampling to a frame rate, conversion to grey and the size check.
#include <cmath>
#include <string>

#include <opencv2/imgproc.hpp>

#include "pliant/vision/webcam_error.hpp"
#include "pliant/vision/webcam_frames.hpp"

namespace pliant::vision::webcam {
namespace {

std::string size_text(const cv::Size& size) { return std::to_string(size.width) + "x" + std::to_string(size.height); }

std::string rate_text(double hz) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", hz);
  return text;
}

}  // namespace

FrameRateSampler::FrameRateSampler(double source_fps_hz, double rate_hz)
    : source_fps_hz_(source_fps_hz), rate_hz_(rate_hz) {
  if (!std::isfinite(rate_hz) || rate_hz < 0) throw InputError("--rate must be a finite rate > 0");
  // A rate a hair above the source's (30 against 29.97) takes every frame.
  if (rate_hz > source_fps_hz * 1.005) {
    throw InputError("--rate " + rate_text(rate_hz) + " Hz is above the source's " + rate_text(source_fps_hz) +
                     " frames per second");
  }
  if (rate_hz == 0 || rate_hz > source_fps_hz) rate_hz_ = source_fps_hz;
}

bool FrameRateSampler::take(int index) {
  // Frame `index` is at index / f; it is the frame nearest to next_ / r when it is the first
  // one past next_ / r - 1 / (2 f), i.e. (index + 1/2) r > next_ f (tiny slack for rounding).
  const double lhs = (index + 0.5) * rate_hz_;
  const double rhs = static_cast<double>(next_) * source_fps_hz_;
  if (lhs <= rhs - 1e-9 * source_fps_hz_) return false;
  ++next_;
  return true;
}

FrameReader::FrameReader(FrameSource& source, double rate_hz) : source_(source), sampler_(source.fps(), rate_hz) {}

double FrameReader::rate_hz() const { return sampler_.rate_hz(); }

int FrameReader::expected_frames() const {
  const int count = source_.frame_count();
  if (count < 0) return -1;
  FrameRateSampler sampler(source_.fps(), sampler_.rate_hz());
  int taken = 0;
  for (int i = 0; i < count; ++i) taken += sampler.take(i) ? 1 : 0;
  return taken;
}

bool FrameReader::next(GreyFrame& frame) {
  std::string label;
  for (;;) {
    if (!source_.read(decoded_, label)) return false;
    const int index = index_++;
    if (!sampler_.take(index)) continue;
    if (decoded_.empty()) throw InputError(label + ": empty frame");
    if (decoded_.depth() != CV_8U) throw InputError(label + ": not an 8-bit image");
    if (size_.empty()) {
      size_ = decoded_.size();
    } else if (decoded_.size() != size_) {
      throw InputError(label + ": " + size_text(decoded_.size()) + ", the first frame is " + size_text(size_));
    }
    switch (decoded_.channels()) {
      case 1: decoded_.copyTo(frame.grey); break;
      case 3: cv::cvtColor(decoded_, frame.grey, cv::COLOR_BGR2GRAY); break;
      case 4: cv::cvtColor(decoded_, frame.grey, cv::COLOR_BGRA2GRAY); break;
      default: throw InputError(label + ": " + std::to_string(decoded_.channels()) + " channels, expected 1, 3 or 4");
    }
    frame.t_s = index / source_.fps();
    frame.source_index = index;
    frame.label = label;
    return true;
  }
}

}  // namespace pliant::vision::webcam
