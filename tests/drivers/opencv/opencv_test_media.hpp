// Test media for the OpenCV driver: frames that carry their index in their colour, written as an
// MJPEG .avi or as PNG files; and a scripted frame source (a fake device).
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <opencv2/core/mat.hpp>

#include "frame_source.hpp"

namespace pliant::drivers::opencv_test {

/// Colour (B, G, R) of frame k (0-based), flat over the frame: distinct per k, far from each other.
cv::Vec3b frame_bgr(int k);
/// A width x height frame of frame_bgr(k).
cv::Mat make_frame(int k, int width, int height);
/// Writes frames 0..count-1 (width x height) into an MJPEG .avi at fps; throws on failure.
void write_video(const std::string& path, int count, double fps, int width = 64, int height = 48);
/// Writes frame k as a PNG (lossless) of the given size; throws on failure.
void write_png(const std::string& path, int k, int width = 32, int height = 24);
/// Writes `bytes` into a file.
void write_bytes(const std::string& path, const std::string& bytes);
/// Index k whose frame_bgr is nearest to `bgr` (within `tolerance` per channel), else -1.
int frame_index_of(const cv::Vec3b& bgr, int count, int tolerance);

/// A live (or file-like) source driven by the test: each permit yields one frame whose pixels
/// all equal the frame's running number (mod 256), of size width x height.
struct FakeScript {
  std::atomic<int> permits{0};          ///< frames the source may yield
  std::atomic<int> yielded{0};          ///< frames yielded so far (all sources of the factory)
  std::atomic<int> calls{0};            ///< next() calls so far
  std::atomic<int> last_yield_call{0};  ///< the call that yielded the last frame
  std::atomic<bool> fail_next{false};   ///< the next call reports disconnected (then the source is dead)
  std::atomic<bool> throw_next{false};  ///< the next call throws
  std::atomic<int> failing_opens{0};    ///< open() fails this many more times
  std::atomic<int> opens{0};            ///< open() calls
  std::atomic<int> width{16};
  std::atomic<int> height{8};
  /// Called by every next() that returns idle, in the thread that calls next(). Set it only
  /// while next() runs in the test's own thread (configure, stepped reads): it may then drive a
  /// ManualClock, which must not be touched from the decoder thread.
  std::function<void()> on_idle;
};

/// Waits (up to 10 s) until the fake yielded `yielded` frames in all and the decoder came back
/// for more, i.e. every yielded frame was handled by the camera; false on timeout.
bool wait_settled(const FakeScript& script, int yielded);
/// Lets the fake yield `frames` more frames (none may be pending) and waits until they are handled.
bool emit_and_settle(FakeScript& script, int frames);

class FakeFactory final : public opencv_detail::SourceFactory {
 public:
  FakeFactory(std::shared_ptr<FakeScript> script, bool live) : script_(std::move(script)), live_(live) {}
  bool live() const noexcept override { return live_; }
  std::unique_ptr<opencv_detail::FrameSource> open(opencv_detail::OpenError& error) override;

 private:
  std::shared_ptr<FakeScript> script_;
  bool live_;
};

}  // namespace pliant::drivers::opencv_test
