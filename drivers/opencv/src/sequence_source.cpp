// Image sequences (a pattern, a glob or a directory), listed and decoded by the shared readers
// (image_files.hpp, file_readers.hpp).
#include <filesystem>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "frame_source.hpp"
#include "pliant/drivers/opencv/file_readers.hpp"
#include "pliant/drivers/opencv/image_files.hpp"
#include "sources.hpp"

namespace pliant::drivers::opencv_detail {

namespace {

// Frame k of a sequence: the file's image, media time k / fps. A file that has gone since the
// listing ends the sequence (a pattern ends at its first missing file); one that cannot be
// decoded is a drop (the next call takes the next file).
class SequenceSource final : public FrameSource {
 public:
  SequenceSource(std::vector<std::string> files, double fps) : files_(std::move(files)), fps_(fps) {}

  SourceStatus next(cv::Mat& image, double& media_s) override {
    if (position_ >= files_.size()) return SourceStatus::end;
    const std::string& path = files_[position_];
    media_s = static_cast<double>(position_) / fps_;
    ++position_;
    image = opencv_files::read_image(path, opencv_files::ImageDecoding::colour8);
    if (!image.empty()) return SourceStatus::frame;
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) {
      position_ = files_.size();
      return SourceStatus::end;
    }
    return SourceStatus::decode_error;
  }

 private:
  std::vector<std::string> files_;
  std::size_t position_ = 0;  ///< frames yielded so far (the media clock)
  double fps_;
};

class SequenceFactory final : public SourceFactory {
 public:
  explicit SequenceFactory(const OpenCvCameraConfig& config)
      : location_(config.location), first_index_(config.first_index), fps_(config.fps > 0 ? config.fps : kDefaultFps) {}
  bool live() const noexcept override { return false; }

  std::unique_ptr<FrameSource> open(OpenError& error) override {
    std::vector<std::string> files;
    if (!opencv_files::list_image_sequence(location_, opencv_files::sequence_form(location_), first_index_, files,
                                           error)) {
      return nullptr;
    }
    return std::make_unique<SequenceSource>(std::move(files), fps_);
  }

 private:
  std::string location_;
  int first_index_;
  double fps_;
};

}  // namespace

std::shared_ptr<SourceFactory> make_sequence_factory(const OpenCvCameraConfig& config) {
  return std::make_shared<SequenceFactory>(config);
}

}  // namespace pliant::drivers::opencv_detail
