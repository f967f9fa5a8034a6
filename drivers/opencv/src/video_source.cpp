// Video files (the shared reader of file_readers.hpp) and V4L2 devices through cv::VideoCapture.
#include <cmath>
#include <filesystem>
#include <limits>
#include <string>
#include <system_error>
#include <utility>

#include <opencv2/videoio.hpp>

#include "frame_source.hpp"
#include "pliant/drivers/opencv/file_readers.hpp"
#include "sources.hpp"

namespace pliant::drivers::opencv_detail {

namespace {

namespace fs = std::filesystem;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// A video file through the shared reader (file_readers.hpp), with the camera's media clock.
class VideoFileSource final : public FrameSource {
 public:
  VideoFileSource(std::unique_ptr<opencv_files::VideoFile> video, double fps)
      : video_(std::move(video)), fps_(fps), announced_(video_->stated_frames()) {}

  SourceStatus next(cv::Mat& image, double& media_s) override {
    if (!video_->read(image)) {
      // Container frame counts may be estimates from the duration: a one-frame shortfall is
      // not reported.
      return (announced_ > 0 && static_cast<double>(frames_) + 1 < announced_) ? SourceStatus::ended_early
                                                                               : SourceStatus::end;
    }
    ++frames_;
    // The backend's position after a read is the frame's presentation time; use it while it
    // increases, else continue from the previous frame at the nominal rate.
    const double position_s = video_->position_s();
    double t = 0;
    if (has_last_) {
      t = (std::isfinite(position_s) && position_s > last_s_) ? position_s : last_s_ + 1.0 / fps_;
    } else {
      t = (std::isfinite(position_s) && position_s >= 0) ? position_s : 0.0;
    }
    last_s_ = t;
    has_last_ = true;
    media_s = t;
    return SourceStatus::frame;
  }

 private:
  std::unique_ptr<opencv_files::VideoFile> video_;
  double fps_;
  double announced_;
  std::uint64_t frames_ = 0;
  double last_s_ = 0;
  bool has_last_ = false;
};

class VideoFileFactory final : public SourceFactory {
 public:
  VideoFileFactory(std::string path, double fallback_fps) : path_(std::move(path)), fallback_fps_(fallback_fps) {}
  bool live() const noexcept override { return false; }

  std::unique_ptr<FrameSource> open(OpenError& error) override {
    std::unique_ptr<opencv_files::VideoFile> video = opencv_files::VideoFile::open(path_, error);
    if (!video) return nullptr;
    const double fps = video->stated_fps() > 0 ? video->stated_fps() : fallback_fps_;
    return std::make_unique<VideoFileSource>(std::move(video), fps);
  }

 private:
  std::string path_;
  double fallback_fps_;
};

class DeviceSource final : public FrameSource {
 public:
  explicit DeviceSource(cv::VideoCapture capture) : capture_(std::move(capture)) {}
  SourceStatus next(cv::Mat& image, double& media_s) override {
    media_s = kNaN;
    if (!capture_.read(image) || image.empty()) return SourceStatus::disconnected;
    return SourceStatus::frame;
  }

 private:
  cv::VideoCapture capture_;
};

class DeviceFactory final : public SourceFactory {
 public:
  explicit DeviceFactory(const OpenCvCameraConfig& config) : config_(config) {}
  bool live() const noexcept override { return true; }

  std::unique_ptr<FrameSource> open(OpenError& error) override {
    error.status = hal::HalStatus::disconnected;
    cv::VideoCapture capture;
    const int index = device_index(config_.location);
    if (index >= 0) {
      if (!capture.open(index, cv::CAP_V4L2)) {
        error.message = "V4L2 device index " + config_.location + ": cannot open (no such device, or busy)";
        return nullptr;
      }
    } else {
      std::error_code ec;
      if (!fs::exists(config_.location, ec)) {
        error.message = "V4L2 device " + config_.location + ": no such device";
        return nullptr;
      }
      if (!capture.open(config_.location, cv::CAP_V4L2)) {
        error.message =
            "V4L2 device " + config_.location + ": cannot open (not a capture device, busy, or permissions)";
        return nullptr;
      }
    }
    if (config_.width > 0) capture.set(cv::CAP_PROP_FRAME_WIDTH, config_.width);
    if (config_.height > 0) capture.set(cv::CAP_PROP_FRAME_HEIGHT, config_.height);
    if (config_.fps > 0) capture.set(cv::CAP_PROP_FPS, config_.fps);
    return std::make_unique<DeviceSource>(std::move(capture));
  }

 private:
  OpenCvCameraConfig config_;
};

}  // namespace

int device_index(const std::string& location) noexcept {
  if (location.empty() || location.size() > 4) return -1;
  int value = 0;
  for (const char c : location) {
    if (c < '0' || c > '9') return -1;
    value = value * 10 + (c - '0');
  }
  return value;
}

std::shared_ptr<SourceFactory> make_video_file_factory(const OpenCvCameraConfig& config) {
  return std::make_shared<VideoFileFactory>(config.location, config.fps > 0 ? config.fps : kDefaultFps);
}

std::shared_ptr<SourceFactory> make_device_factory(const OpenCvCameraConfig& config) {
  return std::make_shared<DeviceFactory>(config);
}

std::shared_ptr<SourceFactory> make_opencv_source_factory(const OpenCvCameraConfig& config) {
  switch (config.source) {
    case OpenCvSource::v4l2_device: return make_device_factory(config);
    case OpenCvSource::video_file: return make_video_file_factory(config);
    case OpenCvSource::image_sequence: return make_sequence_factory(config);
  }
  return nullptr;
}

}  // namespace pliant::drivers::opencv_detail
