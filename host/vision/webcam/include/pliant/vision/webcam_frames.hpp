// Where the webcam front end gets its frames: a video file, an image sequence, or memory; and
// the reader that resamples them to a frame rate, converts them to 8-bit grey and checks that
// every frame has the size of the first.
//
// Time: frame k of a source is at k / fps seconds (the container's rate for a video unless
// overridden, the given rate for an image sequence), so the first frame is at t = 0. Host code:
// allocates, throws InputError (webcam_error.hpp) for unusable input. Not thread-safe: one
// reader per thread.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace pliant::vision::webcam {

/// A sequence of decoded frames in order.
class FrameSource {
 public:
  virtual ~FrameSource() = default;
  /// Decodes the next frame into `image` (8-bit, 1, 3 or 4 channels) and names it in `label`
  /// (the file of an image sequence, "frame N" of a video). Returns false at the end. Throws
  /// InputError when an image of a sequence cannot be read. A video that stops decoding ends
  /// there (OpenCV does not tell a damaged frame from the end).
  virtual bool read(cv::Mat& image, std::string& label) = 0;
  /// Frames per second, finite and > 0.
  virtual double fps() const = 0;
  /// Frames the source expects to deliver, or -1 when unknown (only for progress reports).
  virtual int frame_count() const = 0;
  /// The input as the user named it, for messages and recording metadata.
  virtual const std::string& name() const = 0;
};

/// Opens `input` through the opencv driver's file readers (pliant/drivers/opencv/image_files.hpp
/// and file_readers.hpp, the one reader of files in pliant), unless it is an existing file:
///   - a printf-style pattern with one integer conversion ("frames/f_%04d.png"; %d, %i, %u with
///     an optional '0' flag and width, %% a literal '%'): the files for consecutive numbers from
///     0 (or from 1 when 0 does not exist) up to the first gap;
///   - a glob ("frames/*.png", any of * ? [): the matching files in byte order of their names;
///   - otherwise a video file (OpenCV's FFmpeg back end, else its MJPEG reader).
/// `fps_hz` > 0 sets the frame rate (overriding a video's); 0 takes a video's own rate, and
/// `sequence_fps_hz` for an image sequence (which has none; 0 then refuses the sequence). Rates
/// are finite, > 0 and at most 1000 Hz (drivers::opencv_files::valid_file_rate).
/// Throws InputError when nothing can be opened: no matching file, a missing, unreadable or
/// undecodable video, a directory, a video without a stated rate and no `fps_hz`, a rate out of
/// range. The message is the reader's, one line naming the input.
std::unique_ptr<FrameSource> open_frame_source(const std::string& input, double fps_hz, double sequence_fps_hz = 0);

/// Frames held in memory (tests, callers that decode themselves). Reads copies.
class MemoryFrameSource final : public FrameSource {
 public:
  /// Throws InputError unless fps_hz is finite, > 0 and at most 1000 Hz.
  MemoryFrameSource(std::vector<cv::Mat> frames, double fps_hz, std::string name = "memory");
  bool read(cv::Mat& image, std::string& label) override;
  double fps() const override { return fps_; }
  int frame_count() const override { return static_cast<int>(frames_.size()); }
  const std::string& name() const override { return name_; }

 private:
  std::vector<cv::Mat> frames_;
  double fps_;
  std::string name_;
  std::size_t next_ = 0;
};

/// Expands an image pattern or glob into file names (see open_frame_source); returns an empty
/// list when `input` is neither (a video). Throws InputError when it is a pattern or glob that
/// matches nothing.
std::vector<std::string> expand_image_pattern(const std::string& input);

/// One frame as the tracker uses it.
struct GreyFrame {
  cv::Mat grey;          ///< CV_8UC1, the first frame's size
  double t_s = 0;        ///< seconds since the source's first frame
  int source_index = 0;  ///< index in the source (before resampling)
  std::string label;     ///< names the frame in messages
};

/// Picks frames of a source at a lower rate: with source rate f and target r <= f, source
/// frame k (at k / f) is taken when it is the one nearest to the next multiple of 1 / r, so
/// 30 Hz to 10 Hz takes frames 0, 3, 6, ... Pure logic, no I/O.
class FrameRateSampler {
 public:
  /// rate_hz 0 takes every frame. Throws InputError when rate_hz is not finite, negative, or
  /// above source_fps_hz.
  FrameRateSampler(double source_fps_hz, double rate_hz);
  /// Whether source frame `index` (consecutive calls, from 0) is taken.
  bool take(int index);
  double rate_hz() const { return rate_hz_; }

 private:
  double source_fps_hz_;
  double rate_hz_;
  long long next_ = 0;  // the next multiple of 1 / rate_hz to take
};

/// Reads a source through a FrameRateSampler, converting to grey and checking sizes.
class FrameReader {
 public:
  /// rate_hz as for FrameRateSampler. The reader does not own the source.
  FrameReader(FrameSource& source, double rate_hz);
  /// The next taken frame, or false at the end. Throws InputError when a frame's size differs
  /// from the first one's ("f_0007.png: 320x240, the first frame is 640x480"), when its depth is
  /// not 8 bits, or when it is empty.
  bool next(GreyFrame& frame);
  /// Frames the reader expects to deliver after resampling, -1 when unknown.
  int expected_frames() const;
  double rate_hz() const;
  const FrameSource& source() const { return source_; }

 private:
  FrameSource& source_;
  FrameRateSampler sampler_;
  cv::Size size_;
  int index_ = 0;
  cv::Mat decoded_;
};

}  // namespace pliant::vision::webcam
