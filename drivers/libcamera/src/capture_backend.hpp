// drivers/libcamera internal: what the camera needs from a capture library. libcamera_backend.cpp
// implements it with libcamera; tests implement it with a fake that completes buffers on demand,
// so the request/complete/requeue cycle and the conversions run without a camera.
//
// Cycle: open() (configure) -> start(sink) queues every buffer -> the backend calls
// sink.on_completion() once per completed buffer, from its own thread -> the sink calls
// requeue(buffer) to give the buffer back -> stop() returns when no completion is running or
// will come -> close() (cleanup) unmaps and releases.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "pixel_conversion.hpp"
#include "pliant/drivers/libcamera/libcamera_camera.hpp"
#include "pliant/hal/status.hpp"

namespace pliant::drivers::libcamera_detail {

/// The stream the backend configured.
struct StreamSetup {
  RawFormat format = RawFormat::unsupported;
  int width = 0;
  int height = 0;
  std::size_t stride = 0;  ///< bytes per row of plane 0 (NV12/NV21: of the UV plane too)
  int buffer_count = 0;
  YcbcrMatrix matrix = YcbcrMatrix::bt601;
  bool full_range = false;
  std::string description;  ///< e.g. "640x480-YUYV"
};

/// A mapped buffer: its planes as the camera fills them (read-only views, valid until close()).
/// A single-plane NV12/NV21 buffer has count 1 (the UV rows follow the Y rows).
struct BufferPlanes {
  const std::uint8_t* data[2] = {nullptr, nullptr};
  std::size_t length[2] = {0, 0};
  int count = 0;
};

enum class CompletionStatus : std::uint8_t { success, error, cancelled };

struct Completion {
  int buffer = -1;  ///< index of the buffer, 0..buffer_count-1
  CompletionStatus status = CompletionStatus::success;
  std::uint32_t sequence = 0;          ///< the camera's frame sequence number
  std::uint64_t timestamp_ns = 0;      ///< capture time, CLOCK_MONOTONIC ns (0: unknown)
  std::size_t bytes_used[2] = {0, 0};  ///< per plane as the camera reports it (0: unknown)
};

class CompletionSink {
 public:
  virtual ~CompletionSink() = default;
  /// One buffer is done. Called from the backend's thread, one call at a time.
  virtual void on_completion(const Completion& completion) noexcept = 0;
  /// The camera is gone for good.
  virtual void on_disconnected() noexcept = 0;

 protected:
  CompletionSink() = default;
  CompletionSink(const CompletionSink&) = default;
  CompletionSink& operator=(const CompletionSink&) = default;
};

class CaptureBackend {
 public:
  virtual ~CaptureBackend() = default;
  CaptureBackend(const CaptureBackend&) = delete;
  CaptureBackend& operator=(const CaptureBackend&) = delete;

  /// Acquires and configures the camera, allocates and maps the buffers. On failure: the status
  /// configure returns, `error` in words, nothing held.
  virtual hal::HalStatus open(const LibcameraCameraConfig& config, StreamSetup& setup, std::string& error) = 0;
  /// The planes of buffer `index` (after open).
  virtual BufferPlanes buffer(int index) const noexcept = 0;
  /// Starts capture with every buffer queued; completions go to `sink` until stop().
  virtual hal::HalStatus start(CompletionSink& sink, std::string& error) = 0;
  /// Gives buffer `index` back to the camera (from on_completion); false when the camera refused.
  virtual bool requeue(int index) noexcept = 0;
  /// Stops capture; afterwards no completion is running or will come.
  virtual void stop() noexcept = 0;
  /// Releases what open() acquired (after stop).
  virtual void close() noexcept = 0;

 protected:
  CaptureBackend() = default;
};

}  // namespace pliant::drivers::libcamera_detail
