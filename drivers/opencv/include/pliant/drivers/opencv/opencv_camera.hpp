// pliant drivers/opencv: a hal::ColorCamera over OpenCV's capture and image codecs.
//
// Sources
//   v4l2_device     a webcam through OpenCV's V4L2 backend: `location` is "/dev/videoN" or an
//                   index "N"; width, height and fps are requests (0: the device's default).
//   video_file      a video OpenCV's FFmpeg backend can decode (else its built-in MJPEG reader).
//   image_sequence  still images read with imgcodecs: `location` is a printf-style pattern with
//                   exactly one integer conversion (frame_%04d.png; %d, %Nd, %0Nd; %% is a
//                   literal percent), a glob (frames/*.png: byte order of the names) or a
//                   directory (every file with an image extension, in natural name order: 2.png
//                   before 10.png). A pattern sequence starts at `first_index` (-1: 0, else 1,
//                   whichever file exists) and ends at the first missing index. The files are
//                   listed at configure (image_files.hpp); one that has gone by its turn ends
//                   the sequence.
// Video files and image sequences are read by the driver's file readers (file_readers.hpp,
// image_files.hpp), which the webcam front end uses too.
//
// Frames: every frame is converted to `format` (rgb8, bgr8 or mono8) into a ring of
// `ring_frames` slots allocated at configure and sized from the first frame, which configure
// decodes. ColorFrame::data points into a slot and stays valid until the next read() or stop().
// The delivered size never changes: a later frame of another size is dropped and counted in
// size_mismatches (a HAL frame must not change shape under its consumer; a crop or scale would
// hide that the source changed).
//
// Playback of files
//   real_time  a background thread decodes ahead into the ring; read() delivers the newest frame
//              whose due time has come on the injected Clock and returns no_data before that.
//              The first frame is due at the first start(); frame k at that instant plus its
//              media time minus the first frame's. Time spent stopped pauses the playback. When
//              the loop reads late, the older due frames are passed over (`skipped`, a sequence
//              gap). read() is bounded, allocation-free and never waits for the decoder.
//   stepped    each read() delivers the next frame, decoded in the caller's thread; a frame that
//              cannot be decoded is counted and the next one taken. This read blocks on file I/O
//              and allocates inside OpenCV: it is for offline replay and tests, not for a
//              real-time loop.
// Media time: the backend's position (CAP_PROP_POS_MSEC) when it increases from frame to frame,
// else the previous media time plus 1 / fps (the file's rate; `fps`, or 30, when the file has
// none; image sequences always use `fps`, or 30). Stamps of file frames: their due time, i.e.
// stamp(k) - stamp(0) = media(k) - media(0) plus the time spent stopped, in both modes (so that
// velocities computed between frames are right; in stepped mode advance the clock by the frame
// interval for sample ages to stay meaningful).
// End of stream: when every frame has been delivered or dropped, read() returns no_data for good
// and end_of_stream() is true. A video that ends before the frame count in its header reports
// ended_early (a truncated or damaged file).
//
// Devices (always live): the background thread grabs from configure to cleanup; frames grabbed
// while inactive are discarded. read() delivers the newest frame not yet delivered (older ones
// are skipped). Stamp = clock.now_s() minus the frame's age on std::chrono::steady_clock (the
// time since the grab: a real duration, measured in real time because the grab thread must not
// read the injected Clock, see "Clocks"). When a grab fails the device is lost: read() returns
// disconnected and paces reopen attempts on the injected Clock: the first is due
// reconnect_interval_s after the read that saw the loss, each next one reconnect_interval_s after
// the read that asked for the previous one (later while that attempt still runs). A read at or
// after that time asks the thread to reopen (read() itself never waits for the open; the attempt
// runs in the thread, counted in reconnect_attempts); frames flow again after a successful reopen
// (counted as reconnects by the HAL). No attempt is made while nothing reads (e.g. stopped): with
// a ManualClock, advance it past the interval and read to see the next attempt. stop() and
// cleanup() may wait for a grab in progress (OpenCV's V4L2 timeout).
//
// Sequence numbers: every frame the source yielded takes the next number, delivered or not, so
// every drop (decode error, size mismatch, overrun, skip) is a gap the HAL counts as dropped
// (except drops after the last delivered frame, which no later frame reveals).
//
// Errors at configure: invalid_argument (a bad config value, a malformed pattern, stepped mode
// for a device), disconnected (no such V4L2 device, or it would not open), io_error (a file
// that is missing, unreadable or not decodable; a first frame that cannot be decoded),
// capacity_exceeded (frames too large for the ring), timeout (a non-blocking source gave no first
// frame within 5 s on the injected Clock, or within 5 s of real time: see "Clocks"). last_error()
// says why, in words.
//
// Clocks: every timeout and interval (reconnect pacing, the first-frame wait of configure,
// wait_buffered) is decided on the injected Clock, read only in the thread that drives the camera
// (a ManualClock is not synchronised: the grab thread never reads it). A call that blocks
// (configure's first-frame wait, wait_buffered) is also capped by the same span of real time,
// because a ManualClock cannot move while its only thread waits here; with a SteadyClock both
// limits coincide. Playback due times are on the injected Clock. std::chrono::steady_clock is read
// only for those caps and for the age of a grabbed frame (a stamp correction, not a timeout).
//
// Real-time safety: read() in real_time and device modes is O(ring_frames), allocation-free,
// noexcept and never blocks. configure, start, stop and cleanup are not real-time calls.
// Thread safety: drive the camera from one thread (the HAL rule); the decoder thread is internal.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "pliant/hal/camera.hpp"
#include "pliant/hal/clock.hpp"

namespace pliant::drivers {

enum class OpenCvSource : std::uint8_t { v4l2_device, video_file, image_sequence };
enum class OpenCvPlayback : std::uint8_t { real_time, stepped };

struct OpenCvCameraConfig {
  OpenCvSource source = OpenCvSource::video_file;
  /// Device path or index, file path, or image pattern or directory (see the header comment).
  std::string location;
  hal::PixelFormat format = hal::PixelFormat::rgb8;  ///< delivered pixel format
  int width = 0;   ///< devices: requested width, px, 0..16384 (0: default); files: ignored
  int height = 0;  ///< devices: requested height, px, 0..16384 (0: default); files: ignored
  double fps = 0;  ///< devices: requested rate; files: rate when the file has none; [0, 1000], Hz
  OpenCvPlayback playback = OpenCvPlayback::real_time;  ///< files only (devices: real_time)
  int first_index = -1;                                 ///< image patterns: first index, >= 0 (-1: 0 or 1)
  int ring_frames = 4;                                  ///< decoded frames buffered, 2..64
  double reconnect_interval_s = 0.5;  ///< devices: wait between reopen attempts, (0, 60], injected Clock
};

/// Driver-side counters and stream state (the HAL's DeviceCounters count the reads). Counts are
/// monotonic from configure. Frames "dropped" here are never delivered.
struct OpenCvCameraStats {
  std::uint64_t decoded = 0;             ///< frames the source yielded (including the dropped ones)
  std::uint64_t decode_errors = 0;       ///< frames that could not be decoded (dropped)
  std::uint64_t size_mismatches = 0;     ///< frames of another size than the first (dropped)
  std::uint64_t overruns = 0;            ///< devices: frames discarded because the ring was full (dropped)
  std::uint64_t skipped = 0;             ///< frames passed over by read() for a newer one, or at a disconnect
  std::uint64_t reconnect_attempts = 0;  ///< devices: reopen attempts after a loss
  std::uint64_t reopened = 0;            ///< devices: successful reopens
  bool end_of_stream = false;            ///< files: nothing more will be delivered
  bool ended_early = false;              ///< the video ended before its announced frame count
  bool device_lost = false;              ///< devices: unreachable now (reads return disconnected)
};

namespace opencv_detail {
class SourceFactory;  // drivers/opencv/src/frame_source.hpp (tests inject fake sources)
}  // namespace opencv_detail

class OpenCvCamera final : public hal::ColorCamera {
 public:
  /// Keeps a reference to `clock` (must outlive the camera). Nothing is opened before configure.
  OpenCvCamera(const hal::Clock& clock, OpenCvCameraConfig config);
  /// Internal: frames from `factory` instead of OpenCV (tests; src/frame_source.hpp).
  OpenCvCamera(const hal::Clock& clock, OpenCvCameraConfig config,
               std::shared_ptr<opencv_detail::SourceFactory> factory);
  /// Stops the decoder thread and closes the source (whatever the lifecycle state).
  ~OpenCvCamera() override;

  const OpenCvCameraConfig& config() const noexcept { return config_; }
  /// Why the last configure failed (empty after a successful one).
  const std::string& last_error() const noexcept { return last_error_; }
  /// Frame size and stride fixed at configure (0 before).
  int width() const noexcept;
  int height() const noexcept;
  /// Snapshot of the counters; O(1), allocation-free, noexcept (from the driving thread).
  OpenCvCameraStats stats() const noexcept;
  /// Files: true once every frame was delivered or dropped.
  bool end_of_stream() const noexcept;
  /// Media time of the last delivered frame, s (NaN before the first; devices: NaN).
  double media_time_s() const noexcept { return media_time_s_; }

  /// Blocks until at least `frames` decoded frames wait in the ring (not counting the one held
  /// by the last read), the stream ended, or `timeout_s` passed on the injected Clock or in real
  /// time, whichever comes first (a ManualClock does not move during the wait, so real time is
  /// the cap); true unless it timed out. Not a real-time call: for tests and offline replay of
  /// real_time mode, which otherwise could find the decoder behind. Stepped mode: returns true
  /// at once.
  bool wait_buffered(int frames, double timeout_s) const noexcept;

 protected:
  hal::HalStatus on_configure() override;
  hal::HalStatus on_start() noexcept override;
  hal::HalStatus on_stop() noexcept override;
  hal::HalStatus on_cleanup() noexcept override;
  hal::HalStatus on_read(hal::ColorFrame& out) noexcept override;

 private:
  struct Impl;
  const hal::Clock& clock_;
  OpenCvCameraConfig config_;
  std::shared_ptr<opencv_detail::SourceFactory> factory_;
  std::unique_ptr<Impl> impl_;
  std::string last_error_;
  double media_time_s_;
};

/// Short stable name of a source kind ("v4l2_device", ...), for logs.
const char* opencv_source_name(OpenCvSource source) noexcept;

}  // namespace pliant::drivers
