// pliant drivers/libcamera: a hal::ColorCamera over libcamera 0.0.3 (Debian 12), for UVC webcams
// and the camera pipelines Debian's libcamera was built with (UVC, simple, vimc, IPU3, RkISP1,
// RPi, ISI).
//
// Capture: configure() acquires the camera, asks for one stream of `role`, size and a pixel
// format this driver converts, allocates `buffer_count` buffers with libcamera's
// FrameBufferAllocator and maps them (mmap, read-only). start() queues one request per buffer.
// Each completed request is handled in libcamera's own thread: its buffer is converted into a
// triple buffer of HAL frames (`format`: rgb8, bgr8 or mono8) and the request is queued again at
// once, so the camera never starves while the loop is slow.
// Native formats converted: RGB888, BGR888, XRGB8888, XBGR8888, YUYV, UYVY, NV12, NV21 and R8.
// YUV uses the stream's colour space (BT.601 or BT.709, full or limited range; BT.601 limited
// when libcamera reports none). MJPEG (the default of many UVC webcams) is not decoded: the
// driver picks an uncompressed format the camera offers and configure fails with `unsupported`
// when there is none.
//
// read(): the newest converted frame not yet delivered (older ones were overwritten: counted,
// and a sequence gap); no_data when none arrived since the last read; disconnected once
// libcamera reported the camera gone (it stays so until cleanup; configure again to reopen).
// ColorFrame::data points into the triple buffer and stays valid until the next read() or stop().
// Sequence: from libcamera's frame sequence, so frames the sensor, libcamera or this driver lost
// (failed buffers, conversion errors, overwritten frames) are gaps the HAL counts as dropped.
// Stamp: clock.now_s() minus the frame's age on CLOCK_MONOTONIC, the age taken from libcamera's
// sensor timestamp when it is plausible (0..5 s old), else from the completion time.
//
// Errors at configure: invalid_argument (config values), disconnected (no camera, or no camera
// with `camera_id`), io_error (busy, or libcamera refused a step), unsupported (no convertible
// format), capacity_exceeded. last_error() says why.
//
// libcamera allows one CameraManager per process: every LibcameraCamera (and
// list_libcamera_cameras) shares one, started on first use and stopped when the last user is
// gone.
// Real-time safety: read() is O(1), allocation-free, noexcept and never blocks. The conversion
// runs in libcamera's thread, O(pixels). configure, start, stop, cleanup are not real-time calls.
// Thread safety: drive the camera from one thread (the HAL rule).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "pliant/hal/camera.hpp"
#include "pliant/hal/clock.hpp"

namespace pliant::drivers {

enum class LibcameraRole : std::uint8_t { viewfinder, video_recording, still_capture };

struct LibcameraCameraConfig {
  std::string camera_id;  ///< libcamera's camera id; empty: the first camera listed
  int width = 0;          ///< requested width, px, 0..16384 (0: the pipeline's default for the role)
  int height = 0;         ///< requested height, px, 0..16384 (0: default)
  hal::PixelFormat format = hal::PixelFormat::rgb8;  ///< delivered pixel format
  int buffer_count = 4;                              ///< 2..16 requested (libcamera may adjust)
  LibcameraRole role = LibcameraRole::video_recording;
};

/// Driver-side counters (the HAL's DeviceCounters count the reads). Monotonic from configure.
struct LibcameraCameraStats {
  std::uint64_t completed = 0;          ///< requests completed with a buffer (any status)
  std::uint64_t converted = 0;          ///< frames converted into the triple buffer
  std::uint64_t failed_buffers = 0;     ///< buffers libcamera marked FrameError (dropped)
  std::uint64_t cancelled = 0;          ///< buffers cancelled (at stop; not requeued)
  std::uint64_t conversion_errors = 0;  ///< buffers whose size or bytes used did not fit (dropped)
  std::uint64_t overwritten = 0;        ///< converted frames replaced before a read (dropped)
  std::uint64_t requeue_errors = 0;     ///< requests libcamera refused to queue again
  bool lost = false;                    ///< libcamera reported the camera disconnected
};

namespace libcamera_detail {
class CaptureBackend;  // drivers/libcamera/src/capture_backend.hpp (tests inject a fake)
class FramePipeline;
}  // namespace libcamera_detail

class LibcameraCamera final : public hal::ColorCamera {
 public:
  /// Keeps a reference to `clock` (must outlive the camera). Nothing is opened before configure.
  LibcameraCamera(const hal::Clock& clock, LibcameraCameraConfig config);
  /// Internal: capture through `backend` instead of libcamera (tests).
  LibcameraCamera(const hal::Clock& clock, LibcameraCameraConfig config,
                  std::unique_ptr<libcamera_detail::CaptureBackend> backend);
  /// Stops capture and releases the camera (whatever the lifecycle state).
  ~LibcameraCamera() override;

  const LibcameraCameraConfig& config() const noexcept { return config_; }
  /// Why the last configure failed (empty after a successful one).
  const std::string& last_error() const noexcept { return last_error_; }
  /// The stream libcamera configured, e.g. "640x480-YUYV" (empty before configure).
  const std::string& stream_description() const noexcept { return stream_description_; }
  int width() const noexcept;
  int height() const noexcept;
  /// Snapshot of the counters; O(1), allocation-free, noexcept.
  LibcameraCameraStats stats() const noexcept;

 protected:
  hal::HalStatus on_configure() override;
  hal::HalStatus on_start() noexcept override;
  hal::HalStatus on_stop() noexcept override;
  hal::HalStatus on_cleanup() noexcept override;
  hal::HalStatus on_read(hal::ColorFrame& out) noexcept override;

 private:
  void close() noexcept;

  const hal::Clock& clock_;
  LibcameraCameraConfig config_;
  std::unique_ptr<libcamera_detail::CaptureBackend> backend_;
  std::unique_ptr<libcamera_detail::FramePipeline> pipeline_;
  std::string last_error_;
  std::string stream_description_;
  bool streaming_ = false;
};

/// The ids of the cameras libcamera sees now (empty when none); `error` (optional) says why the
/// list is empty when the CameraManager could not start. Not a real-time call.
std::vector<std::string> list_libcamera_cameras(std::string* error = nullptr);

}  // namespace pliant::drivers
