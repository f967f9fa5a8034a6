// `pliant record`: the devices of a recording, opened through the device registry
// (hal/device_registry.hpp) that the drivers of this build registered in (cli_registry.hpp).
//
// A spec (record_device_spec.hpp) becomes the hal::DeviceSpec its driver registered: the KIND is
// the scheme, the numbers of the spec and the options below are parameters. The recorder asks
//   colour    format bgr8 (what cv::VideoWriter takes); files play in real time, so a file
//             behaves as a camera on the recording clock
//   depth     .oni files play in real time
//   ft        tare when --tare (ATI: 100 samples on start; Robotous: the sensor's bias on start;
//             FT 300: the first sample)
//   gripper   stroke_m from --gripper-stroke
// and leaves the rest to the factories (docs/hal.md lists them: FT 300 stream mode on RTU,
// polled at most every 5 ms over TCP; Robotiq polled at most every 10 ms with activation policy
// `never`: the recorder only reads, it never activates or moves the fingers).
// A spec whose driver this build lacks is refused by check_driver_built() with the Debian
// package to install.
//
// Lifecycle: open_device() constructs and configures (the factory); start(); the loop reads
// through the HAL interfaces; the destructor stops (if active) and cleans up. Errors: configure
// refused with invalid_argument -> UsageError (exit 2); any other configure or start failure ->
// std::runtime_error (exit 1). Both name the option, the spec and the driver's reason.
// Host code: allocates and throws. Thread safety: one thread drives the devices.
#pragma once

#include <memory>
#include <string>

#include <nlohmann/json.hpp>

#include "pliant/hal/camera.hpp"
#include "pliant/hal/clock.hpp"
#include "pliant/hal/device_registry.hpp"
#include "pliant/hal/force_torque.hpp"
#include "pliant/hal/gripper.hpp"
#include "record_device_spec.hpp"

namespace pliant::cli {

struct DeviceOpenOptions {
  bool tare = false;                ///< zero the F/T sensor at start (see the top)
  double gripper_stroke_m = 0.085;  ///< Robotiq 2F: 0.085 (2F-85) or 0.140 (2F-140), the width at full opening
};

/// One opened device. Exactly one of color(), depth(), ft(), gripper() is non-null, by role.
class RecordDevice {
 public:
  RecordDevice(DeviceSpec spec, std::string driver, std::unique_ptr<hal::OpenedDevice> opened);
  RecordDevice(const RecordDevice&) = delete;
  RecordDevice& operator=(const RecordDevice&) = delete;

  const DeviceSpec& spec() const { return spec_; }
  /// "opencv", "libcamera", "openni2", "socketcan", "modbus".
  const char* driver() const { return driver_.c_str(); }
  hal::Device& device() { return opened_->device(); }
  hal::ColorCamera* color() { return opened_->color_camera(); }
  hal::DepthCamera* depth() { return opened_->depth_camera(); }
  hal::ForceTorqueSensor* ft() { return opened_->force_torque(); }
  hal::Gripper* gripper() { return opened_->gripper(); }

  /// inactive -> active, plus what must follow it (FT 300 tare). Throws std::runtime_error.
  void start();
  /// File-backed sources: true once every frame was delivered or dropped.
  bool ended() const { return opened_->ended(); }
  /// Driver counters and facts for recording.json meta (JSON object; hal::DeviceInfo's dotted
  /// names nested).
  nlohmann::json driver_info() const;

 private:
  DeviceSpec spec_;
  std::string driver_;
  std::unique_ptr<hal::OpenedDevice> opened_;  // stops and cleans up the device when destroyed
};

/// The device category of a role.
hal::DeviceCategory device_category(DeviceRole role) noexcept;

/// The hal::DeviceSpec of `spec` with `options` as parameters (see the top).
hal::DeviceSpec to_hal_spec(const DeviceSpec& spec, const DeviceOpenOptions& options);

/// Throws UsageError when the driver of `spec` is not part of this build, naming the Debian
/// package that brings it ("... install libopenni2-dev and rebuild").
void check_driver_built(const DeviceSpec& spec);

/// Constructs the device of `spec` on `clock` (which must outlive it) and configures it.
/// Throws as described at the top.
std::unique_ptr<RecordDevice> open_device(const DeviceSpec& spec, const hal::Clock& clock,
                                          const DeviceOpenOptions& options);

}  // namespace pliant::cli
