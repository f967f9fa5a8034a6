#include "track_depth_input.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <string>
#include <utility>

#include "cli_registry.hpp"
#include "pliant/hal/clock.hpp"
#include "pliant/hal/device_registry.hpp"
#include "pliant/vision/depth_list.hpp"

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

// The depth camera scheme that plays .oni recordings (drivers/openni2 registers it).
constexpr const char* kOniScheme = "oni";

class OniInput final : public DepthInput {
 public:
  explicit OniInput(const std::string& path) {
    kind = "OpenNI recording";
    hal::ManualClock clock;  // declared before the device, which keeps a reference to it
    hal::DeviceSpec spec;
    spec.scheme = kOniScheme;
    spec.location = path;
    spec.parameters["playback"] = "stepped";
    hal::OpenResult opened = cli_registry().devices.open(hal::DeviceCategory::depth_camera, spec, clock);
    if (!opened) throw vision::DepthError(path + ": " + opened.error);
    hal::OpenedDevice& device = *opened.device;
    hal::DepthCamera& camera = *device.depth_camera();
    if (device.start() != hal::HalStatus::ok) {
      throw vision::DepthError(path + ": cannot start playback: " + device.last_error());
    }
    std::size_t bytes = 0;
    while (!device.ended()) {
      hal::DepthFrame frame;
      const hal::HalStatus status = camera.read(frame);
      if (status == hal::HalStatus::no_data) continue;  // ended() decides
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
    if (cli_registry().devices.find(hal::DeviceCategory::depth_camera, kOniScheme) == nullptr) {
      throw vision::DepthError(path +
                               ": .oni recordings need drivers/openni2, which this build left out "
                               "(install libopenni2-dev and rebuild)");
    }
    return std::make_unique<OniInput>(path);
  }
  return std::make_unique<ListInput>(path);
}

}  // namespace pliant::cli
