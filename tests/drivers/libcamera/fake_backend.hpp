// A CaptureBackend without a camera: buffers are plain memory the test fills, completions are
// delivered when the test calls complete() (on the caller's thread), requeues are recorded.
#pragma once

#include <atomic>
#include <cstdint>
#include <string>
#include <vector>

#include "capture_backend.hpp"

namespace pliant::drivers::libcamera_test {

struct FakeBackendState {
  libcamera_detail::StreamSetup setup;
  int planes_per_buffer = 1;  ///< 2: NV12/NV21 as two planes
  hal::HalStatus open_status = hal::HalStatus::ok;
  std::string open_error;
  hal::HalStatus start_status = hal::HalStatus::ok;
  bool refuse_requeue = false;
  std::vector<std::vector<std::uint8_t>> buffers;  ///< [buffer][plane 0 | plane 1 bytes]
  std::size_t plane0_bytes = 0;                    ///< split point when planes_per_buffer == 2
  // Recorded.
  std::vector<int> queued;  ///< buffers the camera holds (queued, not completed)
  std::atomic<int> requeues{0};
  int starts = 0, stops = 0, opens = 0, closes = 0;
  libcamera_detail::CompletionSink* sink = nullptr;
  bool running = false;
};

class FakeBackend final : public libcamera_detail::CaptureBackend {
 public:
  explicit FakeBackend(FakeBackendState& state) : state_(state) {}
  hal::HalStatus open(const LibcameraCameraConfig& config, libcamera_detail::StreamSetup& setup,
                      std::string& error) override;
  libcamera_detail::BufferPlanes buffer(int index) const noexcept override;
  hal::HalStatus start(libcamera_detail::CompletionSink& sink, std::string& error) override;
  bool requeue(int index) noexcept override;
  /// Like libcamera: every queued buffer completes as cancelled before stop returns.
  void stop() noexcept override;
  void close() noexcept override;

 private:
  FakeBackendState& state_;
};

/// Sizes the buffers of `state` for its setup: `count` buffers of `bytes` each.
void make_buffers(FakeBackendState& state, int count, std::size_t bytes);

/// Completes buffer `index` (removing it from the queued list) with the given metadata.
void complete(FakeBackendState& state, int index, libcamera_detail::CompletionStatus status, std::uint32_t sequence,
              std::uint64_t timestamp_ns = 0, std::size_t bytes_used = 0);

}  // namespace pliant::drivers::libcamera_test
