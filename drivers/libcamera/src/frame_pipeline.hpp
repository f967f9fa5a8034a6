// drivers/libcamera internal: the completion side of the camera. Converts each completed buffer
// into a triple buffer of HAL frames in the backend's thread, requeues the buffer at once, and
// hands the newest frame to read() in the loop's thread.
//
// Triple buffer: the producer writes the back slot and swaps it with the middle one (marked
// fresh); the consumer swaps its front slot with the middle one when fresh. Both swaps are one
// atomic exchange: no locks, no waiting, and a frame the consumer holds is never written.
// Sequence numbers: the camera's sequence mapped to 1, 2, ... from the first frame after
// configure (a jump in the camera's sequence is a jump here; a restart after stop continues).
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "capture_backend.hpp"
#include "pliant/hal/camera.hpp"
#include "pliant/hal/clock.hpp"

namespace pliant::drivers::libcamera_detail {

/// CLOCK_MONOTONIC, ns.
std::uint64_t monotonic_now_ns() noexcept;

class FramePipeline final : public CompletionSink {
 public:
  using NowNs = std::uint64_t (*)() noexcept;

  /// Sizes three output frames for `setup` in `format`; `backend` receives the requeues.
  /// Allocates; throws std::bad_alloc. `now_ns` is the monotonic clock (tests inject one).
  FramePipeline(const StreamSetup& setup, hal::PixelFormat format, CaptureBackend& backend,
                NowNs now_ns = &monotonic_now_ns);

  /// Before the backend starts: completions are converted and requeued from now on.
  void begin() noexcept;
  /// After the backend stopped: later completions are not requeued; the held frame is released.
  void end() noexcept;

  void on_completion(const Completion& completion) noexcept override;
  void on_disconnected() noexcept override;

  /// The newest frame not yet taken: ok, no_data, or disconnected once the camera is gone.
  /// The frame stays valid until the next take() or end(). O(1), allocation-free.
  hal::HalStatus take(hal::ColorFrame& out, const hal::Clock& clock) noexcept;

  LibcameraCameraStats stats() const noexcept;
  int width() const noexcept { return setup_.width; }
  int height() const noexcept { return setup_.height; }

 private:
  struct SlotMeta {
    std::uint64_t sequence = 0;
    std::uint64_t capture_ns = 0;
  };
  static constexpr unsigned kFresh = 4u;  // in middle_: slot index | kFresh

  bool convert(const Completion& completion, std::uint8_t* out) noexcept;

  StreamSetup setup_;
  hal::PixelFormat format_;
  CaptureBackend& backend_;
  NowNs now_ns_;
  std::size_t stride_ = 0;
  std::size_t slot_bytes_ = 0;
  std::vector<std::uint8_t> storage_;  // three slots
  SlotMeta meta_[3];

  // Producer (the backend's thread).
  unsigned back_ = 0;
  bool have_sequence_ = false;
  std::uint32_t last_camera_sequence_ = 0;
  std::uint64_t last_sequence_ = 0;

  // Shared.
  std::atomic<unsigned> middle_{1};
  std::atomic<bool> running_{false};
  std::atomic<bool> lost_{false};
  std::atomic<std::uint64_t> completed_{0};
  std::atomic<std::uint64_t> converted_{0};
  std::atomic<std::uint64_t> failed_{0};
  std::atomic<std::uint64_t> cancelled_{0};
  std::atomic<std::uint64_t> conversion_errors_{0};
  std::atomic<std::uint64_t> overwritten_{0};
  std::atomic<std::uint64_t> requeue_errors_{0};

  // Consumer (the loop's thread).
  unsigned front_ = 2;
};

}  // namespace pliant::drivers::libcamera_detail
