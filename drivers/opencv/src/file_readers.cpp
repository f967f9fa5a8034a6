// Video files and still images through OpenCV's videoio and imgcodecs (file_readers.hpp).
#include "pliant/drivers/opencv/file_readers.hpp"

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <limits>
#include <system_error>
#include <utility>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

namespace pliant::drivers::opencv_files {

namespace {

namespace fs = std::filesystem;

// Opens `path` with one back end; an OpenCV exception counts as a refusal.
bool open_with(cv::VideoCapture& capture, const std::string& path, int api) {
  try {
    if (capture.open(path, api)) return true;
  } catch (const cv::Exception&) {
  }
  capture.release();
  return false;
}

// The file checks before decoding; an empty string when the file can be handed to OpenCV.
std::string file_problem(const std::string& path) {
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (!fs::exists(status)) return "no such file";
  if (fs::is_directory(status)) return "is a directory, not a regular file";
  if (!fs::is_regular_file(status)) return "not a regular file";
  if (::access(path.c_str(), R_OK) != 0) return "not readable (permissions)";
  return "";
}

}  // namespace

struct VideoFile::Capture {
  cv::VideoCapture capture;
};

VideoFile::VideoFile(std::string path, std::unique_ptr<Capture> capture)
    : path_(std::move(path)), capture_(std::move(capture)) {
  const double fps = capture_->capture.get(cv::CAP_PROP_FPS);
  stated_fps_ = valid_file_rate(fps) ? fps : 0.0;
  const double frames = capture_->capture.get(cv::CAP_PROP_FRAME_COUNT);
  stated_frames_ = std::isfinite(frames) && frames > 0 ? frames : 0.0;
}

VideoFile::~VideoFile() = default;

std::unique_ptr<VideoFile> VideoFile::open(const std::string& path, FileError& error) {
  error.status = hal::HalStatus::io_error;
  const std::string problem = file_problem(path);
  if (!problem.empty()) {
    error.message = "video file " + path + ": " + problem;
    return nullptr;
  }
  auto capture = std::make_unique<Capture>();
  if (!open_with(capture->capture, path, cv::CAP_FFMPEG) && !open_with(capture->capture, path, cv::CAP_OPENCV_MJPEG)) {
    error.message = "video file " + path +
                    ": cannot open the video: OpenCV cannot decode it (not a video, damaged, or an unknown codec; "
                    "FFmpeg and MJPEG back ends tried)";
    return nullptr;
  }
  return std::unique_ptr<VideoFile>(new VideoFile(path, std::move(capture)));
}

bool VideoFile::read(cv::Mat& image) {
  try {
    return capture_->capture.read(image) && !image.empty();
  } catch (const cv::Exception&) {
    return false;
  }
}

double VideoFile::position_s() const {
  const double ms = capture_->capture.get(cv::CAP_PROP_POS_MSEC);
  return std::isfinite(ms) ? ms / 1000.0 : std::numeric_limits<double>::quiet_NaN();
}

cv::Mat read_image(const std::string& path, ImageDecoding decoding) {
  try {
    return cv::imread(path, decoding == ImageDecoding::as_stored ? cv::IMREAD_UNCHANGED : cv::IMREAD_COLOR);
  } catch (const cv::Exception&) {
    return cv::Mat();
  }
}

}  // namespace pliant::drivers::opencv_files
