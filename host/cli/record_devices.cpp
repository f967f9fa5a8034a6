#include "record_devices.hpp"

#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <utility>

#include "exit_status.hpp"

#if PLIANT_HAVE_DRIVER_OPENCV
#include "pliant/drivers/opencv/opencv_camera.hpp"
#endif
#if PLIANT_HAVE_DRIVER_LIBCAMERA
#include "pliant/drivers/libcamera/libcamera_camera.hpp"
#endif
#if PLIANT_HAVE_DRIVER_OPENNI2
#include "pliant/drivers/openni2/openni2_camera.hpp"
#endif
#if PLIANT_HAVE_DRIVER_SOCKETCAN
#include "pliant/drivers/socketcan/ati_netcanoem_sensor.hpp"
#include "pliant/drivers/socketcan/raw_can_transport.hpp"
#include "pliant/drivers/socketcan/robotous_rft_sensor.hpp"
#endif
#if PLIANT_HAVE_DRIVER_MODBUS
#include "pliant/drivers/modbus/robotiq_ft300.hpp"
#include "pliant/drivers/modbus/robotiq_gripper.hpp"
#endif

namespace pliant::cli {
namespace {

using nlohmann::json;

// The prefix of every message about a device: "--ft 'ati-can:can0@0x20'".
std::string who(const DeviceSpec& spec) { return std::string(device_role_option(spec.role)) + " '" + spec.text + "'"; }

// configure() failed with `status`; `reason` is the driver's explanation (may be empty).
[[noreturn, maybe_unused]] void configure_failed(const DeviceSpec& spec, hal::HalStatus status, const std::string& reason) {
  const std::string message = who(spec) + ": cannot open (" + hal::hal_status_name(status) + ")" +
                              (reason.empty() ? std::string() : ": " + reason);
  if (status == hal::HalStatus::invalid_argument) throw UsageError(message);
  throw std::runtime_error(message);
}

// File sources by absolute path: the drivers open them in their own threads, and a library that
// changes the working directory (OpenNI2's initialisation may) must not change what they name.
[[maybe_unused]] std::string file_location(const DeviceSpec& spec) {
  std::error_code ec;
  const std::filesystem::path path = std::filesystem::absolute(spec.location, ec);
  return ec ? spec.location : path.string();
}

[[maybe_unused]] std::string errno_text(int err) {
  if (err <= 0) return std::string();
  if (err < 4096) return std::strerror(err);
  return "Modbus error " + std::to_string(err);  // libmodbus's own codes (EMB*)
}

#if PLIANT_HAVE_DRIVER_OPENCV
class OpenCvDevice final : public RecordDevice {
 public:
  OpenCvDevice(const DeviceSpec& spec, const hal::Clock& clock) : RecordDevice(spec), camera_(clock, config_of(spec)) {
    const hal::HalStatus status = camera_.configure();
    if (status != hal::HalStatus::ok) configure_failed(spec, status, camera_.last_error());
  }
  ~OpenCvDevice() override { shut_down(); }
  const char* driver() const override { return "opencv"; }
  hal::Device& device() override { return camera_; }
  hal::ColorCamera* color() override { return &camera_; }
  bool ended() const override { return camera_.end_of_stream(); }
  json driver_info() const override {
    const drivers::OpenCvCameraStats s = camera_.stats();
    return {{"source", drivers::opencv_source_name(camera_.config().source)},
            {"width", camera_.width()},
            {"height", camera_.height()},
            {"decoded", s.decoded},
            {"decode_errors", s.decode_errors},
            {"size_mismatches", s.size_mismatches},
            {"overruns", s.overruns},
            {"skipped", s.skipped},
            {"reconnect_attempts", s.reconnect_attempts},
            {"reopened", s.reopened},
            {"end_of_stream", s.end_of_stream},
            {"ended_early", s.ended_early}};
  }

 private:
  static drivers::OpenCvCameraConfig config_of(const DeviceSpec& spec) {
    drivers::OpenCvCameraConfig c;
    c.source = spec.kind == DeviceKind::v4l2    ? drivers::OpenCvSource::v4l2_device
               : spec.kind == DeviceKind::video ? drivers::OpenCvSource::video_file
                                                : drivers::OpenCvSource::image_sequence;
    c.location = spec.kind == DeviceKind::v4l2 ? spec.location : file_location(spec);
    c.format = hal::PixelFormat::bgr8;  // what cv::VideoWriter takes
    c.playback = drivers::OpenCvPlayback::real_time;
    c.ring_frames = 8;
    return c;
  }
  drivers::OpenCvCamera camera_;
};
#endif

#if PLIANT_HAVE_DRIVER_LIBCAMERA
class LibcameraDevice final : public RecordDevice {
 public:
  LibcameraDevice(const DeviceSpec& spec, const hal::Clock& clock)
      : RecordDevice(spec), camera_(clock, config_of(spec)) {
    const hal::HalStatus status = camera_.configure();
    if (status != hal::HalStatus::ok) configure_failed(spec, status, camera_.last_error());
  }
  ~LibcameraDevice() override { shut_down(); }
  const char* driver() const override { return "libcamera"; }
  hal::Device& device() override { return camera_; }
  hal::ColorCamera* color() override { return &camera_; }
  json driver_info() const override {
    const drivers::LibcameraCameraStats s = camera_.stats();
    return {{"stream", camera_.stream_description()},
            {"completed", s.completed},
            {"converted", s.converted},
            {"failed_buffers", s.failed_buffers},
            {"conversion_errors", s.conversion_errors},
            {"overwritten", s.overwritten},
            {"lost", s.lost}};
  }

 private:
  static drivers::LibcameraCameraConfig config_of(const DeviceSpec& spec) {
    drivers::LibcameraCameraConfig c;
    c.camera_id = spec.location;  // empty: the first camera
    c.format = hal::PixelFormat::bgr8;
    return c;
  }
  drivers::LibcameraCamera camera_;
};
#endif

#if PLIANT_HAVE_DRIVER_OPENNI2
class Openni2Device final : public RecordDevice {
 public:
  Openni2Device(const DeviceSpec& spec, const hal::Clock& clock) : RecordDevice(spec), camera_(clock, config_of(spec)) {
    const hal::HalStatus status = camera_.configure();
    if (status != hal::HalStatus::ok) configure_failed(spec, status, camera_.last_error());
  }
  ~Openni2Device() override { shut_down(); }
  const char* driver() const override { return "openni2"; }
  hal::Device& device() override { return camera_; }
  hal::DepthCamera* depth() override { return &camera_; }
  bool ended() const override { return camera_.end_of_stream(); }
  json driver_info() const override {
    const drivers::openni2::Openni2CameraStats s = camera_.stats();
    return {{"width", camera_.width()},
            {"height", camera_.height()},
            {"received", s.received},
            {"rejected", s.rejected},
            {"index_resets", s.index_resets},
            {"end_of_stream", s.end_of_stream},
            {"ended_early", s.ended_early},
            {"device_lost", s.device_lost},
            {"intrinsics_source", drivers::openni2::intrinsics_source_name(s.intrinsics_source)}};
  }

 private:
  static drivers::openni2::Openni2CameraConfig config_of(const DeviceSpec& spec) {
    drivers::openni2::Openni2CameraConfig c;
    c.source = spec.kind == DeviceKind::oni ? drivers::openni2::Openni2Source::recording
                                            : drivers::openni2::Openni2Source::device;
    c.location = spec.kind == DeviceKind::oni ? file_location(spec) : spec.location;
    c.playback = drivers::openni2::Openni2Playback::real_time;
    return c;
  }
  drivers::openni2::Openni2Camera camera_;
};
#endif

#if PLIANT_HAVE_DRIVER_SOCKETCAN
namespace can = drivers::socketcan;

can::RawCanConfig raw_can_config(const DeviceSpec& spec) {
  can::RawCanConfig c;
  std::memset(c.interface_name, 0, sizeof c.interface_name);
  spec.location.copy(c.interface_name, sizeof c.interface_name - 1);
  return c;
}

[[noreturn]] void can_configure_failed(const DeviceSpec& spec, hal::HalStatus status, const can::CanTransport& bus) {
  std::string reason;
  if (status == hal::HalStatus::unsupported) reason = "this kernel has no SocketCAN (AF_CAN)";
  if (status == hal::HalStatus::disconnected) {
    reason = "no CAN interface '" + spec.location + "' (plug the adapter in and bring it up: ip link set " +
             spec.location + " up type can bitrate 1000000)";
  }
  if (reason.empty()) reason = errno_text(bus.last_errno());
  configure_failed(spec, status, reason);
}

json link_info(const can::CanLinkCounters& l) {
  return {{"frames_received", l.frames_received}, {"error_frames", l.error_frames},
          {"bus_off_events", l.bus_off_events},   {"rx_overflows", l.rx_overflows},
          {"disconnects", l.disconnects},         {"reconnects", l.reconnects},
          {"untrusted_stamps", l.untrusted_stamps}};
}

class AtiDevice final : public RecordDevice {
 public:
  AtiDevice(const DeviceSpec& spec, const hal::Clock& clock, const DeviceOpenOptions& options)
      : RecordDevice(spec), bus_(raw_can_config(spec)), sensor_(bus_, clock, config_of(spec, options)) {
    const hal::HalStatus status = sensor_.configure();
    if (status != hal::HalStatus::ok) can_configure_failed(spec, status, bus_);
  }
  ~AtiDevice() override { shut_down(); }
  const char* driver() const override { return "socketcan"; }
  hal::Device& device() override { return sensor_; }
  hal::ForceTorqueSensor* ft() override { return &sensor_; }
  json driver_info() const override {
    const can::AtiCounters& p = sensor_.protocol_counters();
    std::string serial;
    for (const char c : sensor_.info().serial) {
      if (c == '\0') break;
      if (c >= 0x20 && c < 0x7f) serial += c;  // the sensor's bytes, printable ASCII only (JSON is UTF-8)
    }
    return {{"serial", serial},
            {"firmware", std::to_string(sensor_.info().firmware_major) + "." +
                             std::to_string(sensor_.info().firmware_minor) + "." +
                             std::to_string(sensor_.info().firmware_build)},
            {"ready", sensor_.ready()},
            {"polls_sent", p.polls_sent},
            {"unanswered_polls", p.unanswered_polls},
            {"incomplete_samples", p.incomplete_samples},
            {"dropped_frames", p.dropped_frames()},
            {"setup_failures", p.setup_failures},
            {"tares_completed", p.tares_completed},
            {"link", link_info(sensor_.link_counters())}};
  }

 private:
  static can::AtiNetCanConfig config_of(const DeviceSpec& spec, const DeviceOpenOptions& options) {
    can::AtiNetCanConfig c;
    c.base_id = static_cast<std::uint8_t>(spec.can_id);
    c.tare_samples_on_start = options.tare ? 100 : 0;
    return c;
  }
  can::RawCanTransport bus_;  // declared first: the sensor holds a reference to it
  can::AtiNetCanForceTorque sensor_;
};

class RobotousDevice final : public RecordDevice {
 public:
  RobotousDevice(const DeviceSpec& spec, const hal::Clock& clock, const DeviceOpenOptions& options)
      : RecordDevice(spec), bus_(raw_can_config(spec)), sensor_(bus_, clock, config_of(spec, options)) {
    const hal::HalStatus status = sensor_.configure();
    if (status != hal::HalStatus::ok) can_configure_failed(spec, status, bus_);
  }
  ~RobotousDevice() override { shut_down(); }
  const char* driver() const override { return "socketcan"; }
  hal::Device& device() override { return sensor_; }
  hal::ForceTorqueSensor* ft() override { return &sensor_; }
  json driver_info() const override {
    const can::RftCounters& p = sensor_.protocol_counters();
    return {{"stream_requests", p.stream_requests},   {"complete_packets", p.complete_packets},
            {"overload_packets", p.overload_packets}, {"incomplete_packets", p.incomplete_packets},
            {"dropped_frames", p.dropped_frames()},   {"link", link_info(sensor_.link_counters())}};
  }

 private:
  static can::RobotousRftConfig config_of(const DeviceSpec& spec, const DeviceOpenOptions& options) {
    can::RobotousRftConfig c;
    c.ids.command = static_cast<std::uint16_t>(spec.can_id);
    c.ids.response_1 = static_cast<std::uint16_t>(spec.can_response_1);
    c.ids.response_2 = static_cast<std::uint16_t>(spec.can_response_2);
    c.bias_on_start = options.tare;
    return c;
  }
  can::RawCanTransport bus_;
  can::RobotousRftForceTorque sensor_;
};
#endif

#if PLIANT_HAVE_DRIVER_MODBUS
namespace mb = drivers::modbus;

void set_link(const DeviceSpec& spec, mb::ModbusLinkConfig& link) {
  const bool tcp = spec.kind == DeviceKind::ft300_tcp || spec.kind == DeviceKind::robotiq_tcp;
  link.transport = tcp ? mb::ModbusTransport::tcp : mb::ModbusTransport::rtu;
  if (tcp) {
    link.host = spec.location;
    link.port = spec.port;
  } else {
    link.device = spec.location;
  }
  link.slave_id = spec.slave_id;
}

json modbus_link_info(const mb::ModbusLinkCounters& l) {
  return {{"transactions", l.transactions}, {"failures", l.failures},       {"timeouts", l.timeouts},
          {"bad_responses", l.bad_responses}, {"disconnects", l.disconnects}, {"reconnects", l.reconnects}};
}

class RobotiqGripperDevice final : public RecordDevice {
 public:
  RobotiqGripperDevice(const DeviceSpec& spec, const hal::Clock& clock, double stroke_m)
      : RecordDevice(spec), gripper_(clock, config_of(spec, stroke_m)) {
    const hal::HalStatus status = gripper_.configure();
    if (status != hal::HalStatus::ok) {
      configure_failed(spec, status, errno_text(gripper_.link_counters().last_errno));
    }
  }
  ~RobotiqGripperDevice() override { shut_down(); }
  const char* driver() const override { return "modbus"; }
  hal::Device& device() override { return gripper_; }
  hal::Gripper* gripper() override { return &gripper_; }
  json driver_info() const override {
    return {{"stroke_m", gripper_.config().scaling.stroke_m},
            {"activated", gripper_.activated()},
            {"fc03", gripper_.using_holding_registers()},
            {"polls_skipped", gripper_.driver_counters().polls_skipped},
            {"link", modbus_link_info(gripper_.link_counters())}};
  }

 private:
  static mb::RobotiqGripperConfig config_of(const DeviceSpec& spec, double stroke_m) {
    mb::RobotiqGripperConfig c;
    set_link(spec, c.link);
    c.scaling.stroke_m = stroke_m;
    c.activation = mb::ActivationPolicy::never;  // the recorder only watches
    c.min_poll_period_s = 0.01;
    return c;
  }
  mb::RobotiqGripper gripper_;
};

class Ft300Device final : public RecordDevice {
 public:
  Ft300Device(const DeviceSpec& spec, const hal::Clock& clock, const DeviceOpenOptions& options)
      : RecordDevice(spec), sensor_(clock, config_of(spec)), tare_(options.tare) {
    const hal::HalStatus status = sensor_.configure();
    if (status != hal::HalStatus::ok) configure_failed(spec, status, errno_text(sensor_.link_counters().last_errno));
  }
  ~Ft300Device() override { shut_down(); }
  const char* driver() const override { return "modbus"; }
  hal::Device& device() override { return sensor_; }
  hal::ForceTorqueSensor* ft() override { return &sensor_; }
  json driver_info() const override {
    json info = {{"mode", sensor_.config().mode == mb::Ft300Mode::stream ? "stream" : "polling"},
                 {"tares", sensor_.driver_counters().tares}};
    if (sensor_.config().mode == mb::Ft300Mode::stream) {
      const mb::RobotiqFt300Counters& d = sensor_.driver_counters();
      info["stream_timeouts"] = d.stream_timeouts;
      info["reconnects"] = d.reconnects;
    } else {
      info["link"] = modbus_link_info(sensor_.link_counters());
    }
    return info;
  }

 protected:
  void after_start() override {
    if (tare_) sensor_.request_tare();
  }

 private:
  static mb::RobotiqFt300Config config_of(const DeviceSpec& spec) {
    mb::RobotiqFt300Config c;
    set_link(spec, c.link);
    c.mode = spec.kind == DeviceKind::ft300_rtu ? mb::Ft300Mode::stream : mb::Ft300Mode::polling;
    c.min_poll_period_s = 0.005;
    return c;
  }
  mb::RobotiqFt300 sensor_;
  bool tare_;
};
#endif

enum class Driver { opencv, libcamera, openni2, socketcan, modbus };

Driver driver_of(DeviceKind kind) {
  switch (kind) {
    case DeviceKind::v4l2:
    case DeviceKind::video:
    case DeviceKind::images: return Driver::opencv;
    case DeviceKind::libcamera: return Driver::libcamera;
    case DeviceKind::openni2:
    case DeviceKind::oni: return Driver::openni2;
    case DeviceKind::ati_can:
    case DeviceKind::robotous_can: return Driver::socketcan;
    case DeviceKind::ft300_rtu:
    case DeviceKind::ft300_tcp:
    case DeviceKind::robotiq_rtu:
    case DeviceKind::robotiq_tcp: return Driver::modbus;
  }
  return Driver::opencv;
}

}  // namespace

void RecordDevice::start() {
  const hal::HalStatus status = device().start();
  if (status != hal::HalStatus::ok) {
    throw std::runtime_error(who(spec_) + ": cannot start (" + hal::hal_status_name(status) + ")");
  }
  after_start();
}

void RecordDevice::shut_down() noexcept {
  hal::Device& d = device();
  if (d.state() == hal::LifecycleState::active) (void)d.stop();
  if (d.state() == hal::LifecycleState::inactive) (void)d.cleanup();
}

void check_driver_built(const DeviceSpec& spec) {
  const char* missing = nullptr;  // name of the driver and its Debian package
  switch (driver_of(spec.kind)) {
    case Driver::opencv:
#if !PLIANT_HAVE_DRIVER_OPENCV
      missing = "drivers/opencv; install libopencv-dev";
#endif
      break;
    case Driver::libcamera:
#if !PLIANT_HAVE_DRIVER_LIBCAMERA
      missing = "drivers/libcamera; install libcamera-dev";
#endif
      break;
    case Driver::openni2:
#if !PLIANT_HAVE_DRIVER_OPENNI2
      missing = "drivers/openni2; install libopenni2-dev";
#endif
      break;
    case Driver::socketcan:
#if !PLIANT_HAVE_DRIVER_SOCKETCAN
      missing = "drivers/socketcan; install linux-libc-dev";
#endif
      break;
    case Driver::modbus:
#if !PLIANT_HAVE_DRIVER_MODBUS
      missing = "drivers/modbus; install libmodbus-dev";
#endif
      break;
  }
  if (missing != nullptr) {
    throw UsageError(who(spec) + ": this pliant was built without " + missing + " and rebuild");
  }
}

std::unique_ptr<RecordDevice> open_device(const DeviceSpec& spec, const hal::Clock& clock,
                                          const DeviceOpenOptions& options) {
  check_driver_built(spec);
  (void)clock;
  (void)options;
  switch (spec.kind) {
#if PLIANT_HAVE_DRIVER_OPENCV
    case DeviceKind::v4l2:
    case DeviceKind::video:
    case DeviceKind::images: return std::make_unique<OpenCvDevice>(spec, clock);
#endif
#if PLIANT_HAVE_DRIVER_LIBCAMERA
    case DeviceKind::libcamera: return std::make_unique<LibcameraDevice>(spec, clock);
#endif
#if PLIANT_HAVE_DRIVER_OPENNI2
    case DeviceKind::openni2:
    case DeviceKind::oni: return std::make_unique<Openni2Device>(spec, clock);
#endif
#if PLIANT_HAVE_DRIVER_SOCKETCAN
    case DeviceKind::ati_can: return std::make_unique<AtiDevice>(spec, clock, options);
    case DeviceKind::robotous_can: return std::make_unique<RobotousDevice>(spec, clock, options);
#endif
#if PLIANT_HAVE_DRIVER_MODBUS
    case DeviceKind::ft300_rtu:
    case DeviceKind::ft300_tcp: return std::make_unique<Ft300Device>(spec, clock, options);
    case DeviceKind::robotiq_rtu:
    case DeviceKind::robotiq_tcp: return std::make_unique<RobotiqGripperDevice>(spec, clock, options.gripper_stroke_m);
#endif
    default: break;
  }
  throw UsageError(who(spec) + ": no driver for this kind in this build");  // check_driver_built said otherwise
}

}  // namespace pliant::cli
