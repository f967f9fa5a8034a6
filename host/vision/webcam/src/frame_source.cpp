// Frame sources: video files and image sequences through the opencv driver's file readers (the
// one reader of files in pliant: drivers/opencv file_readers.hpp, image_files.hpp), frames in
// memory, and the dispatch between them.
#include <cmath>
#include <filesystem>
#include <memory>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "pliant/drivers/opencv/file_readers.hpp"
#include "pliant/drivers/opencv/image_files.hpp"
#include "pliant/vision/webcam_error.hpp"
#include "pliant/vision/webcam_frames.hpp"

namespace pliant::vision::webcam {
namespace {

// A rate the user states (--fps, a sequence's rate, frames in memory): high-speed footage is
// allowed. A rate a video container states is checked by the driver's valid_file_rate (at most
// 1000 Hz: above that, containers report their time base, not a frame rate).
bool valid_given_rate(double hz) { return std::isfinite(hz) && hz > 0 && hz <= 1e6; }

namespace files = drivers::opencv_files;

bool is_regular_file(const std::string& path) {
  std::error_code error;
  return std::filesystem::is_regular_file(path, error);
}

// A video at the rate given (> 0) or, with 0, at the rate its container states.
class VideoSource final : public FrameSource {
 public:
  VideoSource(std::string name, double fps_hz) : name_(std::move(name)) {
    files::FileError error;
    video_ = files::VideoFile::open(name_, error);
    if (!video_) throw InputError(error.message);
    fps_ = fps_hz > 0 ? fps_hz : video_->stated_fps();
    if (fps_ == 0) throw InputError(name_ + ": the video does not state its frame rate; give it (--fps)");
    const double count = video_->stated_frames();
    frame_count_ = count >= 1 && count < 1e9 ? static_cast<int>(count) : -1;
  }

  bool read(cv::Mat& image, std::string& label) override {
    if (!video_->read(image)) return false;
    label = name_ + " frame " + std::to_string(index_++);
    return true;
  }
  double fps() const override { return fps_; }
  int frame_count() const override { return frame_count_; }
  const std::string& name() const override { return name_; }

 private:
  std::string name_;
  std::unique_ptr<files::VideoFile> video_;
  double fps_ = 0;
  int frame_count_ = -1;
  int index_ = 0;
};

// The listed files of a pattern or glob, decoded as stored (FrameReader refuses what is not 8-bit).
class ImageSequenceSource final : public FrameSource {
 public:
  ImageSequenceSource(std::string name, std::vector<std::string> paths, double fps_hz)
      : name_(std::move(name)), paths_(std::move(paths)), fps_(fps_hz) {}

  bool read(cv::Mat& image, std::string& label) override {
    if (next_ >= paths_.size()) return false;
    label = paths_[next_++];
    if (!is_regular_file(label)) throw InputError(label + ": no such file (removed while reading?)");
    image = files::read_image(label, files::ImageDecoding::as_stored);
    if (image.empty()) throw InputError(label + ": cannot read the image (missing, damaged or not an image)");
    return true;
  }
  double fps() const override { return fps_; }
  int frame_count() const override { return static_cast<int>(paths_.size()); }
  const std::string& name() const override { return name_; }

 private:
  std::string name_;
  std::vector<std::string> paths_;
  double fps_;
  std::size_t next_ = 0;
};

}  // namespace

std::vector<std::string> expand_image_pattern(const std::string& input) {
  // An existing file is a video even when its name has a '%' or a '*'.
  if (is_regular_file(input)) return {};
  const files::SequenceForm form = files::sequence_form(input);
  if (form != files::SequenceForm::pattern && form != files::SequenceForm::glob) return {};
  std::vector<std::string> paths;
  files::FileError error;
  if (!files::list_image_sequence(input, form, -1, paths, error)) throw InputError(error.message);
  return paths;
}

std::unique_ptr<FrameSource> open_frame_source(const std::string& input, double fps_hz, double sequence_fps_hz) {
  if (!(fps_hz == 0 || valid_given_rate(fps_hz))) throw InputError("--fps must be a finite rate > 0, at most 1e6 Hz");
  if (!(sequence_fps_hz == 0 || valid_given_rate(sequence_fps_hz)))
    throw InputError("the image sequence rate must be > 0, at most 1e6 Hz");
  if (input.empty()) throw InputError("no video or image pattern given");
  std::vector<std::string> paths = expand_image_pattern(input);
  if (!paths.empty()) {
    const double rate = fps_hz > 0 ? fps_hz : sequence_fps_hz;
    if (rate == 0) throw InputError(input + ": an image sequence needs its frame rate (--fps)");
    return std::make_unique<ImageSequenceSource>(input, std::move(paths), rate);
  }
  return std::make_unique<VideoSource>(input, fps_hz);
}

MemoryFrameSource::MemoryFrameSource(std::vector<cv::Mat> frames, double fps_hz, std::string name)
    : frames_(std::move(frames)), fps_(fps_hz), name_(std::move(name)) {
  if (!valid_given_rate(fps_hz)) throw InputError(name_ + ": the frame rate must be finite, > 0 and at most 1e6 Hz");
}

bool MemoryFrameSource::read(cv::Mat& image, std::string& label) {
  if (next_ >= frames_.size()) return false;
  frames_[next_].copyTo(image);
  label = name_ + " frame " + std::to_string(next_);
  ++next_;
  return true;
}

}  // namespace pliant::vision::webcam
