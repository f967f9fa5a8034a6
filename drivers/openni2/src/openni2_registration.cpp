#include "pliant/drivers/openni2/openni2_registration.hpp"

#include <filesystem>
#include <memory>
#include <string>
#include <system_error>
#include <utility>

#include "pliant/drivers/openni2/openni2_camera.hpp"

namespace pliant::drivers {
namespace {

class OpenedOpenni2Camera final : public hal::OpenedDevice {
 public:
  OpenedOpenni2Camera(const hal::Clock& clock, openni2::Openni2CameraConfig config)
      : camera_(clock, std::move(config)) {}
  ~OpenedOpenni2Camera() override { shut_down(camera_); }
  hal::Device& device() noexcept override { return camera_; }
  hal::DepthCamera* depth_camera() noexcept override { return &camera_; }
  bool ended() const noexcept override { return camera_.end_of_stream(); }
  std::string last_error() const override { return camera_.last_error(); }
  hal::DeviceInfo info() const override {
    const openni2::Openni2CameraStats s = camera_.stats();
    hal::DeviceInfo info;
    info.add("width", camera_.width())
        .add("height", camera_.height())
        .add("received", s.received)
        .add("rejected", s.rejected)
        .add("index_resets", s.index_resets)
        .add("end_of_stream", s.end_of_stream)
        .add("ended_early", s.ended_early)
        .add("device_lost", s.device_lost)
        .add("intrinsics_source", openni2::intrinsics_source_name(s.intrinsics_source));
    return info;
  }

 private:
  openni2::Openni2Camera camera_;
};

std::string absolute_path(const std::string& location) {
  std::error_code ec;
  const std::filesystem::path path = std::filesystem::absolute(location, ec);
  return ec ? location : path.string();
}

hal::OpenResult open_camera(openni2::Openni2CameraConfig config, const hal::Clock& clock) {
  auto opened = std::make_unique<OpenedOpenni2Camera>(clock, std::move(config));
  const hal::HalStatus status = opened->device().configure();
  if (status != hal::HalStatus::ok) return hal::OpenResult::failure(status, opened->last_error());
  return hal::OpenResult::success(std::move(opened));
}

}  // namespace

void register_openni2_devices(hal::DeviceRegistry& registry) {
  registry.add({hal::DeviceCategory::depth_camera,
                "openni2",
                "openni2",
                "any, or an OpenNI2 device URI",
                "a PrimeSense-family depth camera (Xtion, Carmine, Kinect v1) in its current depth mode",
                {}},
               [](const hal::DeviceSpec& spec, const hal::Clock& clock) {
                 openni2::Openni2CameraConfig c;
                 c.source = openni2::Openni2Source::device;
                 c.location = spec.location;
                 return open_camera(std::move(c), clock);
               });
  registry.add({hal::DeviceCategory::depth_camera,
                "oni",
                "openni2",
                "an .oni recording",
                "an OpenNI recording played as a camera (real time) or frame by frame",
                {"playback"}},
               [](const hal::DeviceSpec& spec, const hal::Clock& clock) {
                 openni2::Openni2CameraConfig c;
                 c.source = openni2::Openni2Source::recording;
                 c.location = absolute_path(spec.location);
                 c.playback = spec.choice("playback", {"real_time", "stepped"}, "real_time") == "stepped"
                                  ? openni2::Openni2Playback::stepped
                                  : openni2::Openni2Playback::real_time;
                 return open_camera(std::move(c), clock);
               });
}

}  // namespace pliant::drivers
