// Image sequences (a printf-style pattern or a directory) read with imgcodecs.
#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include <opencv2/imgcodecs.hpp>

#include "frame_source.hpp"
#include "image_sequence.hpp"
#include "sources.hpp"

namespace pliant::drivers::opencv_detail {

namespace {

namespace fs = std::filesystem;

bool is_file(const std::string& path) {
  std::error_code ec;
  return fs::is_regular_file(path, ec);
}

// Frame k of a sequence: the file's image, media time k / fps. A file that is missing (pattern:
// the end) or cannot be decoded (a drop: the next call takes the next file) is reported as such.
class SequenceSource final : public FrameSource {
 public:
  SequenceSource(SequencePattern pattern, std::uint64_t first_index, double fps)
      : pattern_(std::move(pattern)), next_index_(first_index), fps_(fps) {}
  SequenceSource(std::vector<std::string> files, double fps) : files_(std::move(files)), listed_(true), fps_(fps) {}

  SourceStatus next(cv::Mat& image, double& media_s) override {
    std::string path;
    if (listed_) {
      if (position_ >= files_.size()) return SourceStatus::end;
      path = files_[position_];
    } else {
      path = sequence_name(pattern_, next_index_);
      if (!is_file(path)) return SourceStatus::end;
      ++next_index_;
    }
    media_s = static_cast<double>(position_) / fps_;
    ++position_;
    image = cv::imread(path, cv::IMREAD_COLOR);
    return image.empty() ? SourceStatus::decode_error : SourceStatus::frame;
  }

 private:
  SequencePattern pattern_;
  std::vector<std::string> files_;
  bool listed_ = false;
  std::uint64_t next_index_ = 0;
  std::size_t position_ = 0;  ///< frames yielded so far (the media clock)
  double fps_;
};

class SequenceFactory final : public SourceFactory {
 public:
  explicit SequenceFactory(const OpenCvCameraConfig& config)
      : location_(config.location), first_index_(config.first_index), fps_(config.fps > 0 ? config.fps : kDefaultFps) {}
  bool live() const noexcept override { return false; }

  std::unique_ptr<FrameSource> open(OpenError& error) override {
    std::error_code ec;
    if (fs::is_directory(location_, ec)) return open_directory(error);
    SequencePattern pattern;
    if (!parse_sequence_pattern(location_, pattern, error.message)) {
      error.status = hal::HalStatus::invalid_argument;
      error.message += ": " + location_;
      return nullptr;
    }
    error.status = hal::HalStatus::io_error;
    std::uint64_t first = 0;
    if (first_index_ >= 0) {
      first = static_cast<std::uint64_t>(first_index_);
      if (!is_file(sequence_name(pattern, first))) {
        error.message = "image sequence " + location_ + ": no file " + sequence_name(pattern, first);
        return nullptr;
      }
    } else if (is_file(sequence_name(pattern, 0))) {
      first = 0;
    } else if (is_file(sequence_name(pattern, 1))) {
      first = 1;
    } else {
      error.message = "image sequence " + location_ + ": no file matches (tried " + sequence_name(pattern, 0) +
                      " and " + sequence_name(pattern, 1) + ")";
      return nullptr;
    }
    return std::make_unique<SequenceSource>(std::move(pattern), first, fps_);
  }

 private:
  std::unique_ptr<FrameSource> open_directory(OpenError& error) {
    error.status = hal::HalStatus::io_error;
    std::vector<std::string> names;
    std::error_code ec;
    for (fs::directory_iterator it(location_, ec), end; !ec && it != end; it.increment(ec)) {
      const std::string name = it->path().filename().string();
      std::error_code file_ec;
      if (has_image_extension(name) && it->is_regular_file(file_ec)) names.push_back(name);
    }
    if (ec) {
      error.message = "image directory " + location_ + ": cannot list (" + ec.message() + ")";
      return nullptr;
    }
    if (names.empty()) {
      error.message = "image directory " + location_ + ": no image files";
      return nullptr;
    }
    std::sort(names.begin(), names.end(),
              [](const std::string& a, const std::string& b) { return natural_less(a, b); });
    std::vector<std::string> files;
    files.reserve(names.size());
    for (const std::string& name : names) files.push_back((fs::path(location_) / name).string());
    return std::make_unique<SequenceSource>(std::move(files), fps_);
  }

  std::string location_;
  int first_index_;
  double fps_;
};

}  // namespace

std::shared_ptr<SourceFactory> make_sequence_factory(const OpenCvCameraConfig& config) {
  return std::make_shared<SequenceFactory>(config);
}

}  // namespace pliant::drivers::opencv_detail
