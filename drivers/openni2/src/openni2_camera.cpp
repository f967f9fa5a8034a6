#include "pliant/drivers/openni2/openni2_camera.hpp"

#include <OpenNI.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <thread>
#include <utility>

#include "openni2_runtime.hpp"

namespace pliant::drivers::openni2 {

using hal::HalStatus;

namespace {

// Real time, only for the teardown grace: it waits for OpenNI2's own threads, which run in real
// time whatever the injected Clock says. Every stream timeout reads the injected Clock.
using SteadyTime = std::chrono::steady_clock::time_point;

double seconds_since(SteadyTime then, SteadyTime now) noexcept {
  return std::chrono::duration<double>(now - then).count();
}

bool in_range(double value, double low, double high) noexcept {
  return std::isfinite(value) && value >= low && value <= high;
}

bool in_open_low(double value, double low, double high) noexcept {
  return std::isfinite(value) && value > low && value <= high;
}

// Debian's DummyDevice answers these URIs (never enumerated).
bool is_dummy_uri(const char* uri) noexcept {
  return std::strcmp(uri, "Dummy") == 0 || std::strcmp(uri, "Oz") == 0 || std::strcmp(uri, "PingPong") == 0;
}

double depth_scale_of(openni::PixelFormat format) noexcept {
  switch (format) {
    case openni::PIXEL_FORMAT_DEPTH_1_MM: return 1e-3;
    case openni::PIXEL_FORMAT_DEPTH_100_UM: return 1e-4;
    default: return 0;
  }
}

std::string extended_error() { return openni::OpenNI::getExtendedError(); }

// Sets `error` to the reason a configuration is refused; returns invalid_argument.
HalStatus invalid_config(std::string& error, const std::string& why) {
  error = "invalid configuration: " + why;
  return HalStatus::invalid_argument;
}

// Fallback intrinsics are given unless every one of fx, fy, cx, cy is NaN.
bool has_fallback_intrinsics(const DepthIntrinsics& fallback) noexcept {
  return !(std::isnan(fallback.fx) && std::isnan(fallback.fy) && std::isnan(fallback.cx) && std::isnan(fallback.cy));
}

// The configuration's own ranges (the header's), before OpenNI2 is touched.
HalStatus check_config(const Openni2CameraConfig& c, std::string& error) {
  if (c.location.empty()) return invalid_config(error, "location is empty");
  if (!in_open_low(c.playback_speed, 0, 16)) return invalid_config(error, "playback_speed must be in (0, 16]");
  if (c.width < 0 || c.width > kMaxDepthSide || c.height < 0 || c.height > kMaxDepthSide) {
    return invalid_config(error, "width and height must be in 0.." + std::to_string(kMaxDepthSide));
  }
  if (c.fps < 0 || c.fps > 1000) return invalid_config(error, "fps must be in 0..1000");
  if (!in_open_low(c.step_timeout_s, 0, 60)) return invalid_config(error, "step_timeout_s must be in (0, 60]");
  if (!in_open_low(c.stall_timeout_s, 0, 600)) return invalid_config(error, "stall_timeout_s must be in (0, 600]");
  if (!in_range(c.teardown_grace_s, 0, 5)) return invalid_config(error, "teardown_grace_s must be in [0, 5]");
  if (c.source == Openni2Source::device && c.playback == Openni2Playback::stepped) {
    return invalid_config(error, "stepped playback is for recordings only");
  }
  const DepthIntrinsics& fallback = c.fallback_intrinsics;
  if (has_fallback_intrinsics(fallback) && check_intrinsics(fallback) != IntrinsicsCheck::ok) {
    return invalid_config(error,
                          std::string("fallback_intrinsics: ") + intrinsics_check_name(check_intrinsics(fallback)));
  }
  return HalStatus::ok;
}

// Recordings: `location` as OpenNI2's URI (absolute, normalised, at most 255 bytes), checked by
// check_oni_file (into `info` and `check`) before OpenNI2 parses it; `depth` is its first depth
// node, pointing into `info`.
HalStatus check_recording(const std::string& location, std::string& uri, OniFileInfo& info, OniCheck& check,
                          const OniNodeInfo*& depth, std::string& error) {
  std::error_code ec;
  std::filesystem::path path = std::filesystem::absolute(location, ec);
  if (ec) return invalid_config(error, "cannot resolve the path \"" + location + "\"");
  uri = path.lexically_normal().string();
  if (uri.size() > 255) {
    return invalid_config(error, "recording path longer than OpenNI2's 255-byte URI limit: " + uri);
  }
  const OniCheckResult result = check_oni_file(uri, info);
  check = result.status;
  if (!result.ok()) {
    error = "recording refused: " + result.message;
    return HalStatus::io_error;
  }
  depth = info.first_node_of_type(kOniNodeDepth);
  if (depth == nullptr) {
    error = "recording \"" + uri + "\" has no depth stream";
    return HalStatus::io_error;
  }
  return HalStatus::ok;
}

// Devices: the URI to open. "any" is the first device OpenNI2 enumerates that is a USB camera
// (not a Dummy URI, not a recording opened earlier); disconnected when there is none. OpenNI2
// must be initialised.
HalStatus resolve_device_uri(const std::string& location, std::string& uri, std::string& error) {
  uri = location;
  if (uri != "any") return HalStatus::ok;
  openni::Array<openni::DeviceInfo> devices;
  openni::OpenNI::enumerateDevices(&devices);
  uri.clear();
  for (int i = 0; i < devices.getSize() && uri.empty(); ++i) {
    const char* candidate = devices[i].getUri();
    if (candidate == nullptr || is_dummy_uri(candidate) || devices[i].getUsbVendorId() == 0) continue;
    std::error_code ec;
    if (std::filesystem::exists(candidate, ec)) continue;  // a recording opened earlier
    uri = candidate;
  }
  if (uri.empty()) {
    error = "no OpenNI2 depth camera connected (OpenNI2 enumerates " + std::to_string(devices.getSize()) +
            " device(s), none a USB camera; the Dummy test device must be opened by URI \"Dummy\")";
    return HalStatus::disconnected;
  }
  return HalStatus::ok;
}

// Devices: the index among `modes` of the depth mode matching the requested width, height and fps
// (0: any), millimetres preferred; -1 when none matches.
int matching_depth_mode(const openni::Array<openni::VideoMode>& modes, const Openni2CameraConfig& c) {
  int chosen = -1;
  for (int i = 0; i < modes.getSize(); ++i) {
    const openni::VideoMode& mode = modes[i];
    if (depth_scale_of(mode.getPixelFormat()) == 0) continue;
    if ((c.width != 0 && mode.getResolutionX() != c.width) || (c.height != 0 && mode.getResolutionY() != c.height) ||
        (c.fps != 0 && mode.getFps() != c.fps)) {
      continue;
    }
    // Prefer millimetres, then the current format.
    if (chosen < 0 || (mode.getPixelFormat() == openni::PIXEL_FORMAT_DEPTH_1_MM &&
                       modes[chosen].getPixelFormat() != openni::PIXEL_FORMAT_DEPTH_1_MM)) {
      chosen = i;
    }
  }
  return chosen;
}

}  // namespace

struct Openni2Camera::Impl {
  openni::Device device;
  openni::VideoStream stream;
  openni::VideoFrameRef frame;
  std::unique_ptr<detail::DeviceEvents> events;
  bool device_open = false;
  bool stream_created = false;
  bool stream_running = false;
  bool recording = false;
  bool stepped = false;
  bool dummy = false;  // Debian's DummyDevice (see on_stop)
  std::uint64_t received_at_start = 0;
  openni::PixelFormat format = openni::PIXEL_FORMAT_DEPTH_1_MM;
  double depth_scale_m = 1e-3;
  int width = 0;
  int height = 0;
  DepthIntrinsics intrinsics;
  std::vector<std::uint16_t> image;
  std::uint32_t last_frame_number = 0;  // recordings: the depth node's last frame number
  double stall_timeout_s = 0;
  double step_timeout_s = 0;

  // Stream state.
  Openni2CameraStats stats;
  SteadyTime stopped_at{};
  bool ever_stopped = false;
  double last_progress_s = 0;    // clock at the start or the last frame taken
  bool step_waiting = false;     // stepped: a read found no frame and none came since
  double step_wait_since_s = 0;  // clock at the read that began that wait
  // Stepped stamps.
  bool have_anchor = false;
  double anchor_s = 0;  // clock at the first start
  double paused_s = 0;  // clock time spent stopped since
  double clock_at_stop_s = 0;
  bool have_first_ts = false;
  std::uint64_t first_ts_us = 0;
  // Live stamps.
  bool have_offset = false;
  double offset_s = 0;
  // Sequence numbers.
  bool have_index = false;
  std::int64_t index_base = 0;  // sequence = index - index_base
  std::uint64_t last_sequence = 0;

  DepthIntrinsics no_intrinsics;

  // Configure steps (configure_impl runs them in this order). Each returns ok, or a status with
  // the reason in `error`; objects created so far stay for teardown.
  HalStatus open_device(const std::string& uri, std::string& error);
  HalStatus set_playback(double playback_speed, const std::string& uri, std::string& error);
  HalStatus create_depth_stream(const std::string& uri, std::string& error);
  HalStatus select_depth_mode(const Openni2CameraConfig& c, const std::string& uri, std::string& error);
  HalStatus adopt_depth_mode(const std::string& uri, std::string& error);
  HalStatus choose_intrinsics(const DepthIntrinsics& fallback, std::string& error);

  // Read steps (on_read runs them in this order).
  /// Waits for the next frame as the mode allows (see the header) and reads it into `frame`: ok;
  /// no_data when none came (a recording that is over or stalled ends its stream here); io_error.
  HalStatus wait_for_frame(const hal::Clock& clock) noexcept;
  /// Copies `frame` into `image` when it has the configured size and format; releases it.
  bool copy_frame() noexcept;
  /// The HAL sequence number of frame `index`: index minus the base, kept increasing when the
  /// device's index restarts (counted in index_resets).
  std::uint64_t sequence_of(int index) noexcept;
  /// The frame's stamp on the HAL clock (now_s read after the frame arrived): stepped, the
  /// recording's timeline from the first start, pauses added; live, the device stamp plus the
  /// smallest clock offset seen.
  double stamp_of(std::uint64_t ts_us, double now_s) noexcept;
  /// The HAL frame over `image`.
  void fill(double stamp_s, hal::DepthFrame& out) const noexcept;
  void end_stream(bool early) noexcept {
    stats.end_of_stream = true;
    stats.ended_early = early;
    stop_stream();
  }

  void stop_stream() noexcept {
    if (!stream_running) return;
    stream.stop();
    stream_running = false;
    stopped_at = std::chrono::steady_clock::now();
    ever_stopped = true;
  }

  // Releases every OpenNI2 object, after the teardown grace (see the header).
  void teardown(double grace_s) noexcept {
    stop_stream();
    frame.release();
    if (stream_created && ever_stopped && grace_s > 0) {
      const double waited = seconds_since(stopped_at, std::chrono::steady_clock::now());
      if (waited < grace_s) std::this_thread::sleep_for(std::chrono::duration<double>(grace_s - waited));
    }
    if (events) events->detach();
    if (stream_created) stream.destroy();
    stream_created = false;
    if (device_open) device.close();
    device_open = false;
    events.reset();
  }
};

const char* intrinsics_source_name(IntrinsicsSource source) noexcept {
  switch (source) {
    case IntrinsicsSource::none: return "none";
    case IntrinsicsSource::device_fov: return "device_fov";
    case IntrinsicsSource::configured: return "configured";
  }
  return "unknown";
}

Openni2Camera::Openni2Camera(const hal::Clock& clock, Openni2CameraConfig config)
    : clock_(clock), config_(std::move(config)) {}

Openni2Camera::~Openni2Camera() {
  if (impl_) impl_->teardown(config_.teardown_grace_s);
}

int Openni2Camera::width() const noexcept { return impl_ ? impl_->width : 0; }
int Openni2Camera::height() const noexcept { return impl_ ? impl_->height : 0; }

const DepthIntrinsics& Openni2Camera::intrinsics() const noexcept {
  static const DepthIntrinsics none;
  return impl_ ? impl_->intrinsics : none;
}

Openni2CameraStats Openni2Camera::stats() const noexcept { return impl_ ? impl_->stats : Openni2CameraStats{}; }

bool Openni2Camera::end_of_stream() const noexcept { return impl_ && impl_->stats.end_of_stream; }

HalStatus Openni2Camera::on_configure() {
  last_error_.clear();
  last_check_ = OniCheck::ok;
  recording_info_ = OniFileInfo{};
  const HalStatus status = configure_impl();
  if (status != HalStatus::ok && impl_) {
    impl_->teardown(0);  // nothing was started: no grace needed
    impl_.reset();
  }
  return status;
}

// Opens `uri` (a device or a recording, as `recording` says) and listens to its events.
HalStatus Openni2Camera::Impl::open_device(const std::string& uri, std::string& error) {
  if (device.open(uri.c_str()) != openni::STATUS_OK) {
    error = "OpenNI2 cannot open \"" + uri + "\": " + extended_error();
    return recording ? HalStatus::io_error : HalStatus::disconnected;
  }
  device_open = true;
  dummy = !recording && is_dummy_uri(uri.c_str());
  if (device.isFile() != recording) {
    error = recording ? "\"" + uri + "\" did not open as a recording" : "\"" + uri + "\" is a recording, not a device";
    return HalStatus::invalid_argument;
  }
  events = std::make_unique<detail::DeviceEvents>(device.getDeviceInfo().getUri());
  if (!events->attach()) {
    error = "OpenNI2 refused the device event listener: " + extended_error();
    return HalStatus::io_error;
  }
  return HalStatus::ok;
}

// Recordings: no repeat, and the speed (stepped: -1, frame by frame). Before the stream exists,
// so that the player never starts in its default repeat mode.
HalStatus Openni2Camera::Impl::set_playback(double playback_speed, const std::string& uri, std::string& error) {
  openni::PlaybackControl* playback = device.getPlaybackControl();
  if (playback == nullptr || playback->setRepeatEnabled(false) != openni::STATUS_OK ||
      playback->setSpeed(stepped ? -1.0f : static_cast<float>(playback_speed)) != openni::STATUS_OK) {
    error = "OpenNI2 refused the playback settings for \"" + uri + "\": " + extended_error();
    return HalStatus::io_error;
  }
  return HalStatus::ok;
}

HalStatus Openni2Camera::Impl::create_depth_stream(const std::string& uri, std::string& error) {
  if (device.getSensorInfo(openni::SENSOR_DEPTH) == nullptr ||
      stream.create(device, openni::SENSOR_DEPTH) != openni::STATUS_OK) {
    error = "\"" + uri + "\" has no depth sensor: " + extended_error();
    return HalStatus::unsupported;
  }
  stream_created = true;
  return HalStatus::ok;
}

// Devices with a requested width, height or fps: switches the stream to the matching depth mode
// (matching_depth_mode) unless it is already in it.
HalStatus Openni2Camera::Impl::select_depth_mode(const Openni2CameraConfig& c, const std::string& uri,
                                                 std::string& error) {
  const openni::SensorInfo& sensor = stream.getSensorInfo();
  const openni::Array<openni::VideoMode>& modes = sensor.getSupportedVideoModes();
  const openni::VideoMode current = stream.getVideoMode();
  const int chosen = matching_depth_mode(modes, c);
  if (chosen < 0) {
    error = "\"" + uri + "\" has no millimetre depth mode " + std::to_string(c.width) + "x" + std::to_string(c.height) +
            " @ " + std::to_string(c.fps) + " Hz (0: any)";
    return HalStatus::unsupported;
  }
  const openni::VideoMode& mode = modes[chosen];
  const bool same = mode.getResolutionX() == current.getResolutionX() &&
                    mode.getResolutionY() == current.getResolutionY() && mode.getFps() == current.getFps() &&
                    mode.getPixelFormat() == current.getPixelFormat();
  if (!same && stream.setVideoMode(mode) != openni::STATUS_OK) {
    error = "\"" + uri + "\" refused the depth mode: " + extended_error();
    return HalStatus::unsupported;
  }
  return HalStatus::ok;
}

// The stream's mode as it is: format and depth scale (m per unit), size (1..kMaxDepthSide px).
HalStatus Openni2Camera::Impl::adopt_depth_mode(const std::string& uri, std::string& error) {
  const openni::VideoMode mode = stream.getVideoMode();
  format = mode.getPixelFormat();
  depth_scale_m = depth_scale_of(format);
  if (depth_scale_m == 0) {
    error = "\"" + uri + "\" streams depth in pixel format " + std::to_string(static_cast<int>(format)) +
            ", not DEPTH_1_MM or DEPTH_100_UM";
    return HalStatus::unsupported;
  }
  width = mode.getResolutionX();
  height = mode.getResolutionY();
  if (width < 1 || height < 1 || width > kMaxDepthSide || height > kMaxDepthSide) {
    error = "\"" + uri + "\" reports a depth size of " + std::to_string(width) + "x" + std::to_string(height);
    return HalStatus::unsupported;
  }
  return HalStatus::ok;
}

// Intrinsics from the stream's field of view (rad) when it reports a valid one, else the
// fallback (given: it must be for the stream's size), else none (NaN, the stream's size).
HalStatus Openni2Camera::Impl::choose_intrinsics(const DepthIntrinsics& fallback, std::string& error) {
  float hfov = 0, vfov = 0;
  const bool has_h = stream.getProperty(ONI_STREAM_PROPERTY_HORIZONTAL_FOV, &hfov) == openni::STATUS_OK;
  const bool has_v = stream.getProperty(ONI_STREAM_PROPERTY_VERTICAL_FOV, &vfov) == openni::STATUS_OK;
  stats.hfov_rad = has_h ? static_cast<double>(hfov) : std::numeric_limits<double>::quiet_NaN();
  stats.vfov_rad = has_v ? static_cast<double>(vfov) : std::numeric_limits<double>::quiet_NaN();
  DepthIntrinsics from_fov;
  if (has_h && has_v &&
      intrinsics_from_fov(stats.hfov_rad, stats.vfov_rad, width, height, from_fov) == IntrinsicsCheck::ok) {
    intrinsics = from_fov;
    stats.intrinsics_source = IntrinsicsSource::device_fov;
  } else if (has_fallback_intrinsics(fallback)) {
    if (fallback.width != width || fallback.height != height) {
      return invalid_config(error, "fallback_intrinsics are for " + std::to_string(fallback.width) + "x" +
                                       std::to_string(fallback.height) + ", the stream is " + std::to_string(width) +
                                       "x" + std::to_string(height));
    }
    intrinsics = fallback;
    stats.intrinsics_source = IntrinsicsSource::configured;
  } else {
    intrinsics = DepthIntrinsics{};
    intrinsics.width = width;
    intrinsics.height = height;
    stats.intrinsics_source = IntrinsicsSource::none;
  }
  return HalStatus::ok;
}

HalStatus Openni2Camera::configure_impl() {
  const Openni2CameraConfig& c = config_;
  HalStatus status = check_config(c, last_error_);
  if (status != HalStatus::ok) return status;
  impl_ = std::make_unique<Impl>();
  Impl& m = *impl_;
  m.recording = c.source == Openni2Source::recording;
  m.stepped = m.recording && c.playback == Openni2Playback::stepped;
  m.step_timeout_s = c.step_timeout_s;

  std::string uri;
  const OniNodeInfo* depth_node = nullptr;  // recordings: in recording_info_
  if (m.recording) {
    status = check_recording(c.location, uri, recording_info_, last_check_, depth_node, last_error_);
    if (status != HalStatus::ok) return status;
    m.last_frame_number = depth_node->last_frame;
  }
  std::string error;
  if (!detail::ensure_openni2(error)) {
    last_error_ = error;
    return HalStatus::io_error;
  }
  // Each step runs only when every one before it succeeded.
  if (!m.recording) status = resolve_device_uri(c.location, uri, last_error_);
  if (status == HalStatus::ok) status = m.open_device(uri, last_error_);
  if (status == HalStatus::ok && m.recording) status = m.set_playback(c.playback_speed, uri, last_error_);
  if (status == HalStatus::ok) status = m.create_depth_stream(uri, last_error_);
  const bool mode_requested = c.width != 0 || c.height != 0 || c.fps != 0;
  if (status == HalStatus::ok && !m.recording && mode_requested) status = m.select_depth_mode(c, uri, last_error_);
  if (status == HalStatus::ok) status = m.adopt_depth_mode(uri, last_error_);
  if (status == HalStatus::ok) status = m.choose_intrinsics(c.fallback_intrinsics, last_error_);
  if (status != HalStatus::ok) return status;

  if (m.recording) {
    // At least three of the file's largest frame intervals (at the playback speed).
    const double largest_gap_s = static_cast<double>(depth_node->max_timestamp_step_us) * 1e-6 / c.playback_speed;
    m.stall_timeout_s = std::max(c.stall_timeout_s, 3 * largest_gap_s);
  }
  m.image.assign(static_cast<std::size_t>(m.width) * static_cast<std::size_t>(m.height), 0);
  return HalStatus::ok;
}

HalStatus Openni2Camera::on_start() noexcept {
  Impl& m = *impl_;
  if (!m.stats.end_of_stream) {
    if (m.stream.start() != openni::STATUS_OK) {
      last_error_ = "OpenNI2 cannot start the depth stream: " + extended_error();
      return HalStatus::io_error;
    }
    m.stream_running = true;
  }
  const double now_s = clock_.now_s();
  if (!m.have_anchor) {
    m.anchor_s = now_s;
    m.have_anchor = true;
  } else {
    m.paused_s += now_s - m.clock_at_stop_s;
  }
  m.have_offset = false;  // a pause would otherwise count as transport delay
  m.received_at_start = m.stats.received;
  m.last_progress_s = now_s;
  m.step_waiting = false;  // time spent stopped is no wait for the player
  return HalStatus::ok;
}

HalStatus Openni2Camera::on_stop() noexcept {
  Impl& m = *impl_;
  // DummyDevice's frame thread sets its running flag only once it is scheduled: a stop before
  // that is lost and the thread would outlive the stream. One frame proves it is running.
  if (m.dummy && m.stream_running && m.stats.received == m.received_at_start) {
    openni::VideoStream* streams[1] = {&m.stream};
    int ready = -1;
    (void)openni::OpenNI::waitForAnyStream(streams, 1, &ready, 500);
  }
  m.stop_stream();
  m.frame.release();
  m.clock_at_stop_s = clock_.now_s();
  return HalStatus::ok;
}

HalStatus Openni2Camera::on_cleanup() noexcept {
  impl_->teardown(config_.teardown_grace_s);
  impl_.reset();
  return HalStatus::ok;
}

HalStatus Openni2Camera::Impl::wait_for_frame(const hal::Clock& clock) noexcept {
  // Read the end-of-file flag before looking for a frame: the player raises it only after
  // handing over its last frame, so "flag set and nothing pending" means nothing will come.
  const bool end_of_file = recording && events->end_of_file();
  openni::VideoStream* streams[1] = {&stream};
  int ready = -1;
  int timeout_ms = 0;
  if (stepped && !end_of_file) {
    // Block for what is left of step_timeout_s on the injected Clock, but never longer than
    // step_timeout_s of real time: a ManualClock does not move while we block, so its caller
    // sees no_data and advances it (header). The extra millisecond lets a real clock pass the
    // deadline within this read despite the millisecond rounding of the wait.
    const double now_s = clock.now_s();
    if (!step_waiting) {
      step_waiting = true;
      step_wait_since_s = now_s;
    }
    const double left_s = std::min(step_wait_since_s + step_timeout_s - now_s, step_timeout_s);
    if (left_s > 0) timeout_ms = static_cast<int>(std::ceil(left_s * 1000)) + 1;
  }
  const openni::Status waited = openni::OpenNI::waitForAnyStream(streams, 1, &ready, timeout_ms);
  if (waited == openni::STATUS_TIME_OUT) {
    if (recording) {
      const double after_s = clock.now_s();
      const bool timed_out =
          stepped ? after_s - step_wait_since_s >= step_timeout_s : after_s - last_progress_s > stall_timeout_s;
      if (end_of_file || timed_out) end_stream(stats.last_frame_index < static_cast<int>(last_frame_number));
    }
    return HalStatus::no_data;
  }
  if (waited != openni::STATUS_OK) return HalStatus::io_error;
  if (stream.readFrame(&frame) != openni::STATUS_OK || !frame.isValid()) return HalStatus::io_error;
  return HalStatus::ok;
}

bool Openni2Camera::Impl::copy_frame() noexcept {
  const openni::VideoMode mode = frame.getVideoMode();
  const bool copied =
      frame.getWidth() == width && frame.getHeight() == height && mode.getPixelFormat() == format &&
      frame.getStrideInBytes() > 0 && frame.getDataSize() > 0 &&
      copy_depth_image(static_cast<const std::uint8_t*>(frame.getData()), static_cast<std::size_t>(frame.getDataSize()),
                       width, height, static_cast<std::size_t>(frame.getStrideInBytes()), image.data(), image.size());
  frame.release();
  return copied;
}

std::uint64_t Openni2Camera::Impl::sequence_of(int index) noexcept {
  if (!have_index) {
    index_base = recording ? 0 : static_cast<std::int64_t>(index) - 1;
    have_index = true;
  }
  std::int64_t sequence = static_cast<std::int64_t>(index) - index_base;
  if (sequence <= static_cast<std::int64_t>(last_sequence)) {
    ++stats.index_resets;
    sequence = static_cast<std::int64_t>(last_sequence) + 1;
    index_base = static_cast<std::int64_t>(index) - sequence;
  }
  return static_cast<std::uint64_t>(sequence);
}

double Openni2Camera::Impl::stamp_of(std::uint64_t ts_us, double now_s) noexcept {
  const double ts_s = static_cast<double>(ts_us) * 1e-6;
  if (stepped) {
    if (!have_first_ts) {
      first_ts_us = ts_us;
      have_first_ts = true;
    }
    return anchor_s + paused_s + (ts_s - static_cast<double>(first_ts_us) * 1e-6);
  }
  const double observed = now_s - ts_s;
  if (!have_offset || observed < offset_s) offset_s = observed;
  have_offset = true;
  return ts_s + offset_s;
}

void Openni2Camera::Impl::fill(double stamp_s, hal::DepthFrame& out) const noexcept {
  out.header.stamp_s = stamp_s;
  out.header.sequence = last_sequence;
  out.header.status_bits = 0;
  out.width = width;
  out.height = height;
  out.stride_bytes = 2 * width;
  out.depth_scale_m = depth_scale_m;
  out.data = image.data();
  out.fx = intrinsics.fx;
  out.fy = intrinsics.fy;
  out.cx = intrinsics.cx;
  out.cy = intrinsics.cy;
}

HalStatus Openni2Camera::on_read(hal::DepthFrame& out) noexcept {
  Impl& m = *impl_;
  if (m.stats.device_lost) return HalStatus::disconnected;
  if (m.events->disconnected() && !m.recording) {
    m.stats.device_lost = true;
    return HalStatus::disconnected;
  }
  if (m.stats.end_of_stream || !m.stream_running) return HalStatus::no_data;

  const HalStatus waited = m.wait_for_frame(clock_);
  if (waited != HalStatus::ok) return waited;
  ++m.stats.received;
  m.last_progress_s = clock_.now_s();
  m.step_waiting = false;

  const int index = m.frame.getFrameIndex();
  const std::uint64_t ts_us = m.frame.getTimestamp();
  const bool copied = m.copy_frame();
  // The last frame of a recording: stop the stream now (the player would spin on the file end).
  const bool last = m.recording && index >= 0 && static_cast<std::uint32_t>(index) >= m.last_frame_number;
  if (!copied) {
    ++m.stats.rejected;
    if (last) m.end_stream(true);
    return HalStatus::no_data;
  }
  m.last_sequence = m.sequence_of(index);
  m.stats.last_frame_index = index;
  m.stats.last_timestamp_us = ts_us;
  m.fill(m.stamp_of(ts_us, clock_.now_s()), out);
  if (last) m.end_stream(false);
  return HalStatus::ok;
}

}  // namespace pliant::drivers::openni2
