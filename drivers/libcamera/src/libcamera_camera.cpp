// The libcamera colour camera: lifecycle over a CaptureBackend, frames through a FramePipeline
// (contract in the public header).
#include "pliant/drivers/libcamera/libcamera_camera.hpp"

#include <exception>
#include <new>
#include <utility>

#include "capture_backend.hpp"
#include "frame_pipeline.hpp"
#include "libcamera_backend.hpp"

namespace pliant::drivers {

namespace {

using hal::HalStatus;

constexpr int kMaxSide = 16384;

const char* config_problem(const LibcameraCameraConfig& c) noexcept {
  if (c.width < 0 || c.width > kMaxSide || c.height < 0 || c.height > kMaxSide) return "width/height outside 0..16384";
  if ((c.width == 0) != (c.height == 0)) return "give both width and height, or neither";
  if (c.buffer_count < 2 || c.buffer_count > 16) return "buffer_count outside 2..16";
  switch (c.format) {
    case hal::PixelFormat::mono8:
    case hal::PixelFormat::rgb8:
    case hal::PixelFormat::bgr8: break;
    default: return "unknown pixel format";
  }
  switch (c.role) {
    case LibcameraRole::viewfinder:
    case LibcameraRole::video_recording:
    case LibcameraRole::still_capture: break;
    default: return "unknown stream role";
  }
  return "";
}

}  // namespace

LibcameraCamera::LibcameraCamera(const hal::Clock& clock, LibcameraCameraConfig config)
    : LibcameraCamera(clock, std::move(config), nullptr) {}

LibcameraCamera::LibcameraCamera(const hal::Clock& clock, LibcameraCameraConfig config,
                                 std::unique_ptr<libcamera_detail::CaptureBackend> backend)
    : clock_(clock), config_(std::move(config)), backend_(std::move(backend)) {}

LibcameraCamera::~LibcameraCamera() { close(); }

void LibcameraCamera::close() noexcept {
  if (streaming_) {
    if (pipeline_) pipeline_->end();
    if (backend_) backend_->stop();
    streaming_ = false;
  }
  if (pipeline_ && backend_) backend_->close();
  pipeline_.reset();
}

int LibcameraCamera::width() const noexcept { return pipeline_ ? pipeline_->width() : 0; }
int LibcameraCamera::height() const noexcept { return pipeline_ ? pipeline_->height() : 0; }

LibcameraCameraStats LibcameraCamera::stats() const noexcept {
  return pipeline_ ? pipeline_->stats() : LibcameraCameraStats{};
}

HalStatus LibcameraCamera::on_configure() {
  close();
  last_error_.clear();
  stream_description_.clear();
  const char* problem = config_problem(config_);
  if (*problem != '\0') {
    last_error_ = problem;
    return HalStatus::invalid_argument;
  }
  try {
    if (!backend_) backend_ = libcamera_detail::make_libcamera_backend();
    libcamera_detail::StreamSetup setup;
    std::string error;
    const HalStatus opened = backend_->open(config_, setup, error);
    if (opened != HalStatus::ok) {
      last_error_ = error.empty() ? "the camera could not be opened" : error;
      return opened;
    }
    if (setup.format == libcamera_detail::RawFormat::unsupported || setup.width < 1 || setup.height < 1 ||
        setup.width > kMaxSide || setup.height > kMaxSide || setup.buffer_count < 1 ||
        setup.stride < libcamera_detail::raw_row_bytes(setup.format, setup.width)) {
      backend_->close();
      last_error_ = "the backend reported an unusable stream: " + setup.description;
      return HalStatus::io_error;
    }
    pipeline_ = std::make_unique<libcamera_detail::FramePipeline>(setup, config_.format, *backend_);
    stream_description_ = setup.description;
    return HalStatus::ok;
  } catch (const std::bad_alloc&) {
    close();
    last_error_ = "out of memory";
    return HalStatus::capacity_exceeded;
  } catch (const std::exception& e) {
    close();
    last_error_ = e.what();
    return HalStatus::io_error;
  }
}

HalStatus LibcameraCamera::on_start() noexcept {
  pipeline_->begin();
  std::string error;
  HalStatus status = HalStatus::io_error;
  try {
    status = backend_->start(*pipeline_, error);
  } catch (...) {
    status = HalStatus::io_error;
  }
  if (status != HalStatus::ok) {
    pipeline_->end();
    backend_->stop();
    return status;
  }
  streaming_ = true;
  return HalStatus::ok;
}

HalStatus LibcameraCamera::on_stop() noexcept {
  pipeline_->end();  // no requeues from here on
  backend_->stop();  // completes what is queued (cancelled)
  streaming_ = false;
  return HalStatus::ok;
}

HalStatus LibcameraCamera::on_cleanup() noexcept {
  close();
  return HalStatus::ok;
}

HalStatus LibcameraCamera::on_read(hal::ColorFrame& out) noexcept { return pipeline_->take(out, clock_); }

std::vector<std::string> list_libcamera_cameras(std::string* error) {
  std::string message;
  std::vector<std::string> ids;
  try {
    ids = libcamera_detail::libcamera_camera_ids(message);
  } catch (const std::exception& e) {
    message = e.what();
  }
  if (error != nullptr) *error = message;
  return ids;
}

}  // namespace pliant::drivers
