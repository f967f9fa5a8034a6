// pliant drivers/openni2: a hal::DepthCamera over OpenNI2 2.2 (Debian libopenni2-0), for depth
// cameras of the PrimeSense family (Asus Xtion, Carmine; Kinect v1 with libfreenect's OpenNI2
// driver) and for .oni recordings. docs/drivers/openni2.md lists the library's facts.
//
// Sources
//   device     `location` is an OpenNI2 device URI (list_openni2_devices() shows them; Debian's
//              test device answers "Dummy") or "any": the first connected USB device OpenNI2
//              enumerates (recordings opened earlier in the process and the Dummy device are
//              skipped). width, height and fps pick a supported depth mode (0: keep the device's
//              current value).
//   recording  `location` is the path of an .oni file (absolute after resolution: at most 255
//              bytes, OpenNI2's URI limit). Before OpenNI2 opens it, check_oni (oni_file.hpp)
//              walks every record and refuses a malformed file with a reason: OpenNI2's player
//              crashes on some malformed files. Repeat is always off.
//
// Depth format: PIXEL_FORMAT_DEPTH_1_MM (depth_scale_m 1e-3) or DEPTH_100_UM (1e-4); other
// formats (shift values) are refused at configure (unsupported). Frames are copied into a
// buffer sized at configure; DepthFrame::data points into it and stays valid until the next
// read() or stop(). A frame of another size or format than configured is dropped (counted in
// rejected; its index shows as a sequence gap).
//
// Intrinsics: from the depth stream's field of view when it is valid (depth_points.hpp:
// fx = (width / 2) / tan(hfov / 2), ...); else `fallback_intrinsics` when given (they must be
// for the stream's size); else NaN in every frame. stats().intrinsics_source says which.
//
// Playback of recordings
//   stepped    OpenNI2's manual mode (speed -1): the player decodes a frame only when asked,
//              so each read() delivers the next frame of the file, none skipped. This read
//              blocks until the player delivers, for what is left of step_timeout_s on the
//              injected Clock since the read that began waiting for this frame, and never more
//              than step_timeout_s of real time (a blocking call, for offline replay and tests,
//              not for a real-time loop). When the wait ends without a frame: if step_timeout_s
//              has passed on the injected Clock the stream ends (ended_early: in this mode the
//              player only ever waits for us), else read() returns no_data. With a SteadyClock
//              the read that times out ends the stream; a ManualClock does not move while the
//              read blocks, so that read returns no_data and the stream ends at the first read
//              after the caller advanced the clock past the deadline (that read only polls).
//   real_time  the player paces frames by their timestamps (times playback_speed); read()
//              never waits and delivers the newest frame (older unread ones are overwritten
//              by OpenNI2: a sequence gap). If no frame arrives for stall_timeout_s on the
//              injected Clock (at least three times the file's largest frame interval; counted
//              from start() or the last frame) the stream ends (ended_early), at the first read
//              that finds nothing after that: with a ManualClock, when the caller advanced it.
//   End of stream: after the frame with the recording's last frame number is taken from
//   OpenNI2 (delivered, or rejected as damaged), or when OpenNI2 reports the end of the file
//   with nothing left to read, read() returns no_data
//   for good and end_of_stream() is true. The driver stops OpenNI2's stream at that point,
//   which also stops its player from spinning on the exhausted file (libOniFile busy-loops at
//   the end of a file while a stream is started). To replay, cleanup() and configure() again.
//
// Stamps (hal Clock, seconds)
//   stepped recordings: stamp = t0 + (ts - ts_first), t0 the clock at the first start() after
//     configure, ts the frame's timestamp in the file; time spent stopped is added. Advance a
//     ManualClock by the frame interval for sample ages to stay meaningful.
//   devices and real_time recordings: stamp = ts + offset, offset the smallest (read time -
//     ts) seen since the last start(): a stamp is never later than the read that delivered
//     it, transport delay beyond the quickest frame shows as sample age, and device clock
//     drift is followed as far as frames arrive earlier than predicted.
// Sequence numbers: recordings use the file's frame number (1-based, so frames skipped in
// real-time mode are gaps); devices count from 1 at the first frame after configure, following
// the device's frame index; an index that goes backwards (device restart) continues the count
// and is counted in index_resets.
//
// Devices: a disconnect reported by OpenNI2 makes every later read() return disconnected until
// cleanup() and configure() (OpenNI2 needs the device reopened). Not exercised by the tests,
// which have no USB camera.
//
// Errors at configure (last_error() says why, in words): invalid_argument (config values, a
// recording path too long, fallback intrinsics that fail check_intrinsics or do not match the
// stream size), io_error (a recording that is missing, unreadable, malformed or has no depth
// stream; OpenNI2 that cannot initialise, e.g. finds no drivers), disconnected (no such device
// or none connected), unsupported (no depth sensor, no matching or no millimetre depth mode),
// capacity_exceeded (frame buffer allocation).
//
// OpenNI2 lifetime: OpenNI::initialize() runs once per process, at the first configure (it
// changes the process's working directory while it loads its drivers), and the driver never
// calls OpenNI::shutdown(): Debian's DummyDevice does not join its frame thread on stop and
// crashes the process when the drivers are unloaded under it (seen here). Do not call
// OpenNI::shutdown() yourself while a camera is configured.
// Teardown: libOniFile walks its stream list without a lock in its player thread while
// destroying a stream removes an element under the lock (a crash in about 5 % of closings at
// the end of a file, measured here), and DummyDevice's frame thread runs up to a frame period
// after stop. cleanup() therefore waits until teardown_grace_s have passed since the stream
// stopped before destroying it. By then DummyDevice's thread is gone and libOniFile's player is
// idle: it looks at its list only once every 10 ms, a window too short to have been hit in the
// tests (the race cannot be closed from outside the library).
// Clocks: the stream's timeouts (step_timeout_s, stall_timeout_s) are decided on the injected
// Clock, read only in the calling thread (OpenNI2's threads never see it). Two waits are real
// time on purpose, because they wait for OpenNI2's own threads, which run in real time: the
// teardown grace (std::chrono::steady_clock) and stop()'s wait of at most 500 ms for
// DummyDevice's first frame; neither decides anything about the stream.
//
// Real-time safety: read() on devices and real_time recordings never waits, copies one frame
// (O(pixels)) and makes no allocation of its own (OpenNI2's internal threads allocate as they
// decode); noexcept. configure, start, stop, cleanup and stepped reads are not real-time calls.
// Thread safety: drive the camera from one thread (the HAL rule); OpenNI2's callbacks only set
// atomic flags.
#pragma once

#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "pliant/drivers/openni2/depth_points.hpp"
#include "pliant/drivers/openni2/oni_file.hpp"
#include "pliant/hal/camera.hpp"
#include "pliant/hal/clock.hpp"

namespace pliant::drivers::openni2 {

enum class Openni2Source : std::uint8_t { device, recording };
enum class Openni2Playback : std::uint8_t { real_time, stepped };
enum class IntrinsicsSource : std::uint8_t { none, device_fov, configured };

struct Openni2CameraConfig {
  Openni2Source source = Openni2Source::device;
  std::string location = "any";                           ///< device URI or "any"; recording: .oni path
  Openni2Playback playback = Openni2Playback::real_time;  ///< recordings only
  double playback_speed = 1.0;                            ///< real_time recordings: (0, 16], 1 = as recorded
  int width = 0;   ///< devices: depth mode width, px, 0..kMaxDepthSide (0: current)
  int height = 0;  ///< devices: depth mode height, px, 0..kMaxDepthSide (0: current)
  int fps = 0;     ///< devices: depth mode rate, Hz, 0..1000 (0: current)
  /// Used when the stream reports no valid field of view (NaN fields: none).
  DepthIntrinsics fallback_intrinsics;
  /// Stepped: wait for a frame that ends the stream, s on the injected Clock (also the most
  /// real time one read blocks), (0, 60].
  double step_timeout_s = 5.0;
  double stall_timeout_s = 3.0;   ///< real_time recordings: silence that ends the stream, s (Clock), (0, 600]
  double teardown_grace_s = 0.1;  ///< wait between stopping and destroying the stream, real s, [0, 5]
};

struct Openni2CameraStats {
  std::uint64_t received = 0;      ///< frames taken from OpenNI2
  std::uint64_t rejected = 0;      ///< of those, dropped for a size or format mismatch
  std::uint64_t index_resets = 0;  ///< device frame index went backwards
  bool end_of_stream = false;      ///< recordings: nothing more will be delivered
  bool ended_early = false;        ///< the recording's last frame was not delivered (missing or rejected)
  bool device_lost = false;        ///< devices: OpenNI2 reported a disconnect
  IntrinsicsSource intrinsics_source = IntrinsicsSource::none;
  double hfov_rad = std::numeric_limits<double>::quiet_NaN();  ///< as the stream reports it (NaN: not reported)
  double vfov_rad = std::numeric_limits<double>::quiet_NaN();
  std::uint64_t last_timestamp_us = 0;  ///< OpenNI2 timestamp of the last delivered frame
  int last_frame_index = 0;             ///< OpenNI2 frame index of the last delivered frame
};

class Openni2Camera final : public hal::DepthCamera {
 public:
  /// Keeps a reference to `clock` (must outlive the camera). Nothing is opened before configure.
  Openni2Camera(const hal::Clock& clock, Openni2CameraConfig config);
  /// Stops and releases everything (whatever the lifecycle state), with the teardown grace.
  ~Openni2Camera() override;

  const Openni2CameraConfig& config() const noexcept { return config_; }
  /// Why the last configure failed (empty after a successful one).
  const std::string& last_error() const noexcept { return last_error_; }
  /// Recordings: the outcome of the file check at the last configure (ok before any).
  OniCheck last_check() const noexcept { return last_check_; }
  /// Recordings: what check_oni found (empty before configure).
  const OniFileInfo& recording_info() const noexcept { return recording_info_; }
  /// Stream size fixed at configure (0 before).
  int width() const noexcept;
  int height() const noexcept;
  /// The intrinsics every frame carries (NaN fields when none).
  const DepthIntrinsics& intrinsics() const noexcept;
  /// Snapshot of the driver's counters; O(1), noexcept.
  Openni2CameraStats stats() const noexcept;
  bool end_of_stream() const noexcept;

 protected:
  hal::HalStatus on_configure() override;
  hal::HalStatus on_start() noexcept override;
  hal::HalStatus on_stop() noexcept override;
  hal::HalStatus on_cleanup() noexcept override;
  hal::HalStatus on_read(hal::DepthFrame& out) noexcept override;

 private:
  struct Impl;
  hal::HalStatus configure_impl();
  const hal::Clock& clock_;
  Openni2CameraConfig config_;
  std::unique_ptr<Impl> impl_;
  std::string last_error_;
  OniCheck last_check_ = OniCheck::ok;
  OniFileInfo recording_info_;
};

/// One device as OpenNI2 enumerates it.
struct Openni2DeviceEntry {
  std::string uri;
  std::string name;
  std::string vendor;
  std::uint16_t usb_vendor_id = 0;
  std::uint16_t usb_product_id = 0;
};

/// The devices OpenNI2 enumerates (initialising OpenNI2 if needed; the Dummy device is never
/// listed, recordings opened earlier are). False, with `error` set, when OpenNI2 cannot start.
bool list_openni2_devices(std::vector<Openni2DeviceEntry>& out, std::string& error);

/// Where OpenNI2 looks for its drivers: the directory "OpenNI2/Drivers" next to the loaded
/// libOpenNI2.so (Debian: /usr/lib/<arch>/OpenNI2/Drivers), unless /etc/openni2/OpenNI.ini sets
/// [Drivers] Repository. Empty when the library's location cannot be found.
std::string openni2_driver_directory();

const char* intrinsics_source_name(IntrinsicsSource source) noexcept;

}  // namespace pliant::drivers::openni2
