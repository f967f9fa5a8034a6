#include "pliant/drivers/opencv/opencv_registration.hpp"

#include <filesystem>
#include <memory>
#include <string>
#include <system_error>
#include <utility>

#include "pliant/drivers/opencv/opencv_camera.hpp"

namespace pliant::drivers {
namespace {

class OpenedOpenCvCamera final : public hal::OpenedDevice {
 public:
  OpenedOpenCvCamera(const hal::Clock& clock, OpenCvCameraConfig config) : camera_(clock, std::move(config)) {}
  ~OpenedOpenCvCamera() override { shut_down(camera_); }
  hal::Device& device() noexcept override { return camera_; }
  hal::ColorCamera* color_camera() noexcept override { return &camera_; }
  bool ended() const noexcept override { return camera_.end_of_stream(); }
  std::string last_error() const override { return camera_.last_error(); }
  hal::DeviceInfo info() const override {
    const OpenCvCameraStats s = camera_.stats();
    hal::DeviceInfo info;
    info.add("source", opencv_source_name(camera_.config().source))
        .add("width", camera_.width())
        .add("height", camera_.height())
        .add("decoded", s.decoded)
        .add("decode_errors", s.decode_errors)
        .add("size_mismatches", s.size_mismatches)
        .add("overruns", s.overruns)
        .add("skipped", s.skipped)
        .add("reconnect_attempts", s.reconnect_attempts)
        .add("reopened", s.reopened)
        .add("end_of_stream", s.end_of_stream)
        .add("ended_early", s.ended_early);
    return info;
  }

 private:
  OpenCvCamera camera_;
};

std::string absolute_path(const std::string& location) {
  std::error_code ec;
  const std::filesystem::path path = std::filesystem::absolute(location, ec);
  return ec ? location : path.string();
}

hal::PixelFormat format_of(const hal::DeviceSpec& spec) {
  const std::string format = spec.choice("format", {"rgb8", "bgr8", "mono8"}, "bgr8");
  return format == "rgb8"    ? hal::PixelFormat::rgb8
         : format == "mono8" ? hal::PixelFormat::mono8
                             : hal::PixelFormat::bgr8;
}

hal::OpenResult open_camera(OpenCvSource source, const hal::DeviceSpec& spec, const hal::Clock& clock) {
  OpenCvCameraConfig c;
  c.source = source;
  c.location = source == OpenCvSource::v4l2_device ? spec.location : absolute_path(spec.location);
  c.format = format_of(spec);
  if (source != OpenCvSource::v4l2_device) {
    c.playback = spec.choice("playback", {"real_time", "stepped"}, "real_time") == "stepped"
                     ? OpenCvPlayback::stepped
                     : OpenCvPlayback::real_time;
  }
  c.ring_frames = 8;
  auto opened = std::make_unique<OpenedOpenCvCamera>(clock, std::move(c));
  const hal::HalStatus status = opened->device().configure();
  if (status != hal::HalStatus::ok) return hal::OpenResult::failure(status, opened->last_error());
  return hal::OpenResult::success(std::move(opened));
}

}  // namespace

void register_opencv_devices(hal::DeviceRegistry& registry) {
  registry.add({hal::DeviceCategory::color_camera,
                "v4l2",
                "opencv",
                "/dev/videoN, a /dev path, or an index N",
                "a V4L2 webcam through OpenCV",
                {"format"}},
               [](const hal::DeviceSpec& spec, const hal::Clock& clock) {
                 return open_camera(OpenCvSource::v4l2_device, spec, clock);
               });
  registry.add({hal::DeviceCategory::color_camera,
                "video",
                "opencv",
                "a video file",
                "a video file played as a camera (real time) or frame by frame",
                {"format", "playback"}},
               [](const hal::DeviceSpec& spec, const hal::Clock& clock) {
                 return open_camera(OpenCvSource::video_file, spec, clock);
               });
  registry.add({hal::DeviceCategory::color_camera,
                "images",
                "opencv",
                "a printf pattern or a directory of images",
                "an image sequence played as a camera (real time) or frame by frame",
                {"format", "playback"}},
               [](const hal::DeviceSpec& spec, const hal::Clock& clock) {
                 return open_camera(OpenCvSource::image_sequence, spec, clock);
               });
}

}  // namespace pliant::drivers
