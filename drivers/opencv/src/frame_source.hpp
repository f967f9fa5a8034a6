// drivers/opencv internal: where frames come from. The camera (opencv_camera.cpp) decodes only
// through this interface, so tests can feed it scripted sources without OpenCV's capture.
#pragma once

#include <memory>
#include <string>

#include <opencv2/core/mat.hpp>

#include "pliant/drivers/opencv/image_files.hpp"
#include "pliant/drivers/opencv/opencv_camera.hpp"
#include "pliant/hal/status.hpp"

namespace pliant::drivers::opencv_detail {

enum class SourceStatus : std::uint8_t {
  frame,         ///< `image` and `media_s` hold the next frame
  decode_error,  ///< this frame could not be decoded; the next call tries the next one
  end,           ///< no more frames
  ended_early,   ///< no more frames, fewer than the file announced
  disconnected,  ///< (live) the device stopped delivering; the source is unusable
  idle,          ///< nothing yet (a non-blocking backend); the caller retries after a short wait
};

class FrameSource {
 public:
  virtual ~FrameSource() = default;
  FrameSource() = default;
  FrameSource(const FrameSource&) = delete;
  FrameSource& operator=(const FrameSource&) = delete;
  /// Decodes the next frame into `image` (8-bit, 1, 3 or 4 channels, or 16-bit; any size; the
  /// camera converts) and its media time, s, from the source's own origin (NaN: live). May
  /// block (device grab, file I/O) and allocate. Exceptions are caught by the caller.
  virtual SourceStatus next(cv::Mat& image, double& media_s) = 0;
};

/// Why open() failed: the HAL status configure returns, and words for last_error() (the file
/// readers' error type, so their messages pass through unchanged).
using OpenError = opencv_files::FileError;

class SourceFactory {
 public:
  virtual ~SourceFactory() = default;
  SourceFactory() = default;
  SourceFactory(const SourceFactory&) = delete;
  SourceFactory& operator=(const SourceFactory&) = delete;
  /// True for devices (grabbed continuously, newest frame wins, reopened after a loss).
  virtual bool live() const noexcept = 0;
  /// Opens the source (configure, and reopen attempts of a lost device from the decoder
  /// thread); nullptr with `error` filled when it cannot.
  virtual std::unique_ptr<FrameSource> open(OpenError& error) = 0;
};

/// The OpenCV sources for a validated config (video_source.cpp, sequence_source.cpp).
std::shared_ptr<SourceFactory> make_opencv_source_factory(const OpenCvCameraConfig& config);

}  // namespace pliant::drivers::opencv_detail
