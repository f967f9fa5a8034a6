// Frame sources: video files through OpenCV's FFmpeg back end, frames in memory, and the
// dispatch between them and image sequences.
#include <cmath>
#include <filesystem>
#include <limits>
#include <memory>
#include <string>

#include <opencv2/videoio.hpp>
#include <opencv2/videoio/registry.hpp>

#include "image_sequence.hpp"
#include "pliant/vision/webcam_error.hpp"
#include "pliant/vision/webcam_frames.hpp"

namespace pliant::vision::webcam {
namespace {

namespace fs = std::filesystem;

bool valid_rate(double fps_hz) { return std::isfinite(fps_hz) && fps_hz > 0 && fps_hz <= 1e6; }

class VideoSource final : public FrameSource {
 public:
  VideoSource(std::string name, double fps_hz) : name_(std::move(name)) {
    std::error_code error;
    const fs::file_status status = fs::status(name_, error);
    if (!fs::exists(status)) throw InputError(name_ + ": no such file");
    if (fs::is_directory(status)) throw InputError(name_ + ": is a directory, not a video or an image pattern");
    // FFmpeg when OpenCV has it: the generic fallback list would also try GStreamer, which
    // prints its own warnings for files it cannot parse.
    const int api = cv::videoio_registry::hasBackend(cv::CAP_FFMPEG) ? cv::CAP_FFMPEG : cv::CAP_ANY;
    try {
      capture_.open(name_, api);
    } catch (const cv::Exception&) {
      capture_.release();
    }
    if (!capture_.isOpened())
      throw InputError(name_ + ": cannot open the video (not a video, damaged, or an unknown codec)");
    fps_ = fps_hz;
    if (fps_ == 0) {
      fps_ = capture_.get(cv::CAP_PROP_FPS);
      if (!valid_rate(fps_)) throw InputError(name_ + ": the video does not state its frame rate; give it (--fps)");
    }
    const double count = capture_.get(cv::CAP_PROP_FRAME_COUNT);
    frame_count_ = std::isfinite(count) && count >= 1 && count < 1e9 ? static_cast<int>(count) : -1;
  }

  bool read(cv::Mat& image, std::string& label) override {
    bool ok = false;
    try {
      ok = capture_.read(image);
    } catch (const cv::Exception&) {
      ok = false;
    }
    if (!ok || image.empty()) return false;
    label = name_ + " frame " + std::to_string(index_++);
    return true;
  }
  double fps() const override { return fps_; }
  int frame_count() const override { return frame_count_; }
  const std::string& name() const override { return name_; }

 private:
  std::string name_;
  cv::VideoCapture capture_;
  double fps_ = 0;
  int frame_count_ = -1;
  int index_ = 0;
};

}  // namespace

std::unique_ptr<FrameSource> open_frame_source(const std::string& input, double fps_hz, double sequence_fps_hz) {
  if (!(fps_hz == 0 || valid_rate(fps_hz))) throw InputError("--fps must be a finite rate > 0");
  if (!(sequence_fps_hz == 0 || valid_rate(sequence_fps_hz))) throw InputError("the image sequence rate must be > 0");
  if (input.empty()) throw InputError("no video or image pattern given");
  std::vector<std::string> files = expand_image_pattern(input);
  if (!files.empty()) {
    const double rate = fps_hz > 0 ? fps_hz : sequence_fps_hz;
    if (rate == 0) throw InputError(input + ": an image sequence needs its frame rate (--fps)");
    return open_image_sequence(input, std::move(files), rate);
  }
  return std::make_unique<VideoSource>(input, fps_hz);
}

MemoryFrameSource::MemoryFrameSource(std::vector<cv::Mat> frames, double fps_hz, std::string name)
    : frames_(std::move(frames)), fps_(fps_hz), name_(std::move(name)) {
  if (!valid_rate(fps_hz)) throw InputError(name_ + ": the frame rate must be finite and > 0");
}

bool MemoryFrameSource::read(cv::Mat& image, std::string& label) {
  if (next_ >= frames_.size()) return false;
  frames_[next_].copyTo(image);
  label = name_ + " frame " + std::to_string(next_);
  ++next_;
  return true;
}

}  // namespace pliant::vision::webcam
