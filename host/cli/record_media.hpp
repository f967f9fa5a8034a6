// `pliant record`: the colour video and depth images of a recording, encoded and written by a
// background thread so that the device loop never waits for an encoder or the disk.
//
// Files (in the recording directory given at construction):
//   color.avi          Motion-JPEG (cv::VideoWriter, fourcc MJPG), frames in arrival order. Its
//                      container rate is nominal: the median frame interval of the first frames
//                      (up to 10 frames or 0.5 s), 30 Hz when only one frame came. The true
//                      times are in color_frames.csv.
//   color_frames.csv   index,t: frame `index` (0-based) of color.avi was captured at t seconds
//                      on the recording clock.
//   depth/NNNNNN.png   16-bit grey PNG per depth frame (cv::imwrite), raw device units.
//   depth_frames.csv   index,t,file,depth_scale_m,fx,fy,cx,cy: metres per unit and the pinhole
//                      intrinsics of each frame (nan when the device reports none).
//
// push_*() copy the frame (the HAL frame is a view valid until the next read) into a queue of
// at most max_queued_bytes; when the queue is full the frame is dropped and false returned
// (counted by the caller). Colour frames of another size than the first are dropped by the
// thread and counted in size_mismatches(). The first encoder or file error stops the thread:
// error() returns it (one line) and finish() throws it.
// Host code: allocates. Thread safety: push_*, error() and finish() from one thread (the loop);
// the encoder thread is internal.
// This header has no OpenCV dependency: RecordWriter holds a MediaSink, and record_media.cpp
// (compiled when OpenCV is found) registers MediaWriter as the CLI's media part
// (register_record_media, called by the generated registration of cli_registry.hpp).
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "pliant/hal/camera.hpp"

namespace pliant::cli {

struct DepthFrameRow {
  int index = 0;
  double t_s = 0;
  std::string file;  ///< relative to the recording directory, "depth/000000.png"
  double depth_scale_m = 0;
  double fx = 0, fy = 0, cx = 0, cy = 0;
};

struct CliRegistry;

/// The media encoder as RecordWriter uses it (the contract above).
class MediaSink {
 public:
  virtual ~MediaSink() = default;
  MediaSink(const MediaSink&) = delete;
  MediaSink& operator=(const MediaSink&) = delete;

  /// Queues a copy of `frame` taken at `t_s` (recording time, s). False: dropped, queue full.
  virtual bool push_color(const hal::ColorFrame& frame, double t_s) = 0;
  virtual bool push_depth(const hal::DepthFrame& frame, double t_s) = 0;

  /// The first error of the encoder thread, empty while there is none.
  virtual std::string error() const = 0;

  /// Writes what is queued, closes color.avi and writes color_frames.csv and depth_frames.csv
  /// (each only when frames of its kind were written). Throws std::runtime_error on the first
  /// error. Call once.
  virtual void finish() = 0;

  // Results, valid after finish().
  virtual const std::vector<double>& color_times() const = 0;  ///< t of frame i of color.avi
  virtual double color_fps() const = 0;                        ///< container rate of color.avi (0: none)
  virtual int color_width() const = 0;
  virtual int color_height() const = 0;
  virtual const std::vector<DepthFrameRow>& depth_rows() const = 0;
  virtual std::uint64_t size_mismatches() const = 0;  ///< colour frames dropped for their size

 protected:
  MediaSink() = default;
};

/// The OpenCV encoder (record_media.cpp).
class MediaWriter final : public MediaSink {
 public:
  explicit MediaWriter(std::string directory, std::size_t max_queued_bytes = std::size_t{256} << 20);
  ~MediaWriter() override;  ///< stops the thread; queued frames are discarded unless finish() ran

  bool push_color(const hal::ColorFrame& frame, double t_s) override;
  bool push_depth(const hal::DepthFrame& frame, double t_s) override;
  std::string error() const override;
  void finish() override;
  const std::vector<double>& color_times() const override;
  double color_fps() const override;
  int color_width() const override;
  int color_height() const override;
  const std::vector<DepthFrameRow>& depth_rows() const override;
  std::uint64_t size_mismatches() const override;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Sets `registry.media` to MediaWriter, and quiets OpenCV's own log lines (record_media.cpp).
void register_record_media(CliRegistry& registry);

}  // namespace pliant::cli
