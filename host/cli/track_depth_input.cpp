#include "track_depth_input.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <string>
#include <utility>

#include "pliant/vision/depth_list.hpp"

#ifdef PLIANT_HAVE_DRIVER_OPENNI2
#include "pliant/drivers/openni2/openni2_camera.hpp"
#include "pliant/hal/clock.hpp"
#endif

namespace pliant::cli {
namespace {

class ListInput final : public DepthInput {
 public:
  explicit ListInput(const std::string& path) : entries_(vision::read_depth_list(path)) {
    for (const vision::DepthListEntry& entry : entries_) times_.push_back(entry.t_s);
    const vision::DepthListEntry& first = entries_.front();
    depth_scale_m = first.depth_scale_m;
    fx = first.fx;
    fy = first.fy;
    cx = first.cx;
    cy = first.cy;
    kind = std::isnan(first.depth_scale_m) ? "TUM list" : "pliant record depth_frames.csv";
  }
  const std::vector<double>& times_s() const override { return times_; }
  vision::DepthImageView frame(int index) override {
    if (index != current_index_) {
      current_ = vision::read_depth_png(entries_[static_cast<std::size_t>(index)].path);
      current_index_ = index;
    }
    return current_.view();
  }

 private:
  std::vector<vision::DepthListEntry> entries_;
  std::vector<double> times_;
  vision::DepthImage current_;
  int current_index_ = -1;
};

#ifdef PLIANT_HAVE_DRIVER_OPENNI2
class OniInput final : public DepthInput {
 public:
  explicit OniInput(const std::string& path) {
    namespace oni = drivers::openni2;
    kind = "OpenNI recording";
    hal::ManualClock clock;
    oni::Openni2CameraConfig config;
    config.source = oni::Openni2Source::recording;
    config.location = path;
    config.playback = oni::Openni2Playback::stepped;
    oni::Openni2Camera camera(clock, config);
    if (camera.configure() != hal::HalStatus::ok) throw vision::DepthError(path + ": " + camera.last_error());
    if (camera.start() != hal::HalStatus::ok) throw vision::DepthError(path + ": cannot start playback: " + camera.last_error());
    std::size_t bytes = 0;
    while (!camera.end_of_stream()) {
      hal::DepthFrame frame;
      const hal::HalStatus status = camera.read(frame);
      if (status == hal::HalStatus::no_data) continue;  // end_of_stream() decides
      if (status != hal::HalStatus::ok) {
        throw vision::DepthError(path + ": frame " + std::to_string(frames_.size() + 1) + ": " +
                                 hal::hal_status_name(status));
      }
      bytes += static_cast<std::size_t>(frame.width) * static_cast<std::size_t>(frame.height) * sizeof(std::uint16_t);
      if (bytes > kMaxOniBytes) {
        throw vision::DepthError(path + ": more than " + std::to_string(kMaxOniBytes >> 20) +
                                 " MiB of depth frames; record it with `pliant record` and track its depth_frames.csv");
      }
      if (!frames_.empty() && !(frame.header.stamp_s > times_.back())) continue;  // never twice the same time
      vision::DepthImage image;
      image.width = frame.width;
      image.height = frame.height;
      image.data.resize(static_cast<std::size_t>(frame.width) * static_cast<std::size_t>(frame.height));
      const std::size_t row_elements = static_cast<std::size_t>(frame.stride_bytes) / sizeof(std::uint16_t);
      for (int v = 0; v < frame.height; ++v) {
        std::copy_n(frame.data + static_cast<std::size_t>(v) * row_elements, frame.width,
                    image.data.begin() + static_cast<std::ptrdiff_t>(v) * frame.width);
      }
      if (frames_.empty()) {
        depth_scale_m = frame.depth_scale_m;
        fx = frame.fx;
        fy = frame.fy;
        cx = frame.cx;
        cy = frame.cy;
      }
      times_.push_back(frame.header.stamp_s);
      frames_.push_back(std::move(image));
    }
    (void)camera.stop();
    if (frames_.empty()) throw vision::DepthError(path + ": no depth frame in the recording");
    const double t0 = times_.front();
    for (double& t : times_) t -= t0;
  }
  const std::vector<double>& times_s() const override { return times_; }
  vision::DepthImageView frame(int index) override { return frames_[static_cast<std::size_t>(index)].view(); }

 private:
  std::vector<vision::DepthImage> frames_;
  std::vector<double> times_;
};
#endif

}  // namespace

bool is_oni_path(const std::string& path) {
  if (path.size() < 4) return false;
  std::string extension = path.substr(path.size() - 4);
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return extension == ".oni";
}

std::unique_ptr<DepthInput> open_depth_input(const std::string& path) {
  if (is_oni_path(path)) {
#ifdef PLIANT_HAVE_DRIVER_OPENNI2
    return std::make_unique<OniInput>(path);
#else
    throw vision::DepthError(path + ": .oni recordings need drivers/openni2, which this build left out "
                             "(install libopenni2-dev and rebuild)");
#endif
  }
  return std::make_unique<ListInput>(path);
}

}  // namespace pliant::cli
