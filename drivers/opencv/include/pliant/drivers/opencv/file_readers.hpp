// pliant drivers/opencv: video files and still images decoded with OpenCV, as plain readers.
//
// The one implementation of file decoding in pliant: OpenCvCamera's video_file and
// image_sequence sources and the webcam front end (host/vision/webcam) read through these, so
// the back end choice, the checks before decoding and their messages are the same everywhere.
// This is the driver's only public header with OpenCV types (cv::Mat): it is for host code that
// processes images with OpenCV itself; include it only with OpenCV on the include path (link
// opencv_core).
//
// Back end: a video opens with OpenCV's FFmpeg back end, else with OpenCV's own MJPEG reader.
// Never the generic list (CAP_ANY), whose GStreamer back end prints warnings of its own for files
// it cannot parse. OpenCV exceptions are caught: a call that throws inside OpenCV fails instead.
//
// Host-side code: allocates, blocks on file I/O, not real-time. Not thread-safe: one reader per
// thread.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include <opencv2/core/mat.hpp>

#include "pliant/drivers/opencv/image_files.hpp"

namespace pliant::drivers::opencv_files {

/// A video file decoded frame by frame.
class VideoFile {
 public:
  /// Opens `path`; nullptr with `error` (io_error) otherwise, whose message is one of
  ///   "video file <path>: no such file"
  ///   "video file <path>: is a directory, not a regular file"
  ///   "video file <path>: not a regular file"
  ///   "video file <path>: not readable (permissions)"
  ///   "video file <path>: cannot open the video: OpenCV cannot decode it (not a video, damaged,
  ///    or an unknown codec; FFmpeg and MJPEG back ends tried)"
  static std::unique_ptr<VideoFile> open(const std::string& path, FileError& error);
  ~VideoFile();
  VideoFile(const VideoFile&) = delete;
  VideoFile& operator=(const VideoFile&) = delete;

  /// Decodes the next frame into `image` (as the back end delivers it: 8-bit BGR, usually).
  /// false at the end, and at a frame the back end cannot decode (OpenCV does not tell the two
  /// apart), with `image` then unspecified.
  bool read(cv::Mat& image);
  /// The rate the container states, Hz, when valid_file_rate accepts it; else 0 (none stated).
  double stated_fps() const noexcept { return stated_fps_; }
  /// The frame count the container states (an estimate from the duration in some formats);
  /// 0 when it states none.
  double stated_frames() const noexcept { return stated_frames_; }
  /// The back end's position after the last read, s: the presentation time of that frame. NaN
  /// when the back end does not say.
  double position_s() const;
  const std::string& path() const noexcept { return path_; }

 private:
  struct Capture;
  VideoFile(std::string path, std::unique_ptr<Capture> capture);

  std::string path_;
  std::unique_ptr<Capture> capture_;
  double stated_fps_ = 0;
  double stated_frames_ = 0;
};

enum class ImageDecoding : std::uint8_t {
  as_stored,  ///< the file's own depth and channels (8 or 16 bits; grey, grey + alpha, BGR, BGRA)
  colour8,    ///< converted to 8-bit BGR (and turned upright by EXIF orientation)
};

/// Decodes the image file `path` with imgcodecs. An empty matrix when it cannot: missing,
/// damaged, or not an image.
cv::Mat read_image(const std::string& path, ImageDecoding decoding);

}  // namespace pliant::drivers::opencv_files
