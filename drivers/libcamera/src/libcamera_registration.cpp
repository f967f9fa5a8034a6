#include "pliant/drivers/libcamera/libcamera_registration.hpp"

#include <memory>
#include <string>
#include <utility>

#include "pliant/drivers/libcamera/libcamera_camera.hpp"

namespace pliant::drivers {
namespace {

class OpenedLibcameraCamera final : public hal::OpenedDevice {
 public:
  OpenedLibcameraCamera(const hal::Clock& clock, LibcameraCameraConfig config) : camera_(clock, std::move(config)) {}
  ~OpenedLibcameraCamera() override { shut_down(camera_); }
  hal::Device& device() noexcept override { return camera_; }
  hal::ColorCamera* color_camera() noexcept override { return &camera_; }
  std::string last_error() const override { return camera_.last_error(); }
  hal::DeviceInfo info() const override {
    const LibcameraCameraStats s = camera_.stats();
    hal::DeviceInfo info;
    info.add("stream", camera_.stream_description())
        .add("completed", s.completed)
        .add("converted", s.converted)
        .add("failed_buffers", s.failed_buffers)
        .add("conversion_errors", s.conversion_errors)
        .add("overwritten", s.overwritten)
        .add("lost", s.lost);
    return info;
  }

 private:
  LibcameraCamera camera_;
};

}  // namespace

void register_libcamera_devices(hal::DeviceRegistry& registry) {
  registry.add({hal::DeviceCategory::color_camera,
                "libcamera",
                "libcamera",
                "any, or a libcamera camera id",
                "a camera through libcamera (UVC webcams, Raspberry Pi and other ISP pipelines)",
                {"format"}},
               [](const hal::DeviceSpec& spec, const hal::Clock& clock) {
                 LibcameraCameraConfig c;
                 c.camera_id = spec.location == "any" ? std::string() : spec.location;  // empty: the first camera
                 const std::string format = spec.choice("format", {"rgb8", "bgr8", "mono8"}, "bgr8");
                 c.format = format == "rgb8"    ? hal::PixelFormat::rgb8
                            : format == "mono8" ? hal::PixelFormat::mono8
                                                : hal::PixelFormat::bgr8;
                 auto opened = std::make_unique<OpenedLibcameraCamera>(clock, std::move(c));
                 const hal::HalStatus status = opened->device().configure();
                 if (status != hal::HalStatus::ok) return hal::OpenResult::failure(status, opened->last_error());
                 return hal::OpenResult::success(std::move(opened));
               });
}

}  // namespace pliant::drivers
