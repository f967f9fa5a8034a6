// `pliant record`: the devices of a recording, opened through the drivers that were built.
//
// Each driver is optional in the build (drivers/CMakeLists.txt leaves out those whose library
// is missing); host/cli/CMakeLists.txt defines PLIANT_HAVE_DRIVER_<NAME> for those present, and
// only their code is compiled here. A spec for a driver that is not built is refused by
// check_driver_built() with the Debian package to install.
//
// What the recorder asks of the drivers (chosen here, documented in docs/record.md):
//   colour    OpenCvCamera (bgr8; files in real-time playback, so a file behaves as a camera
//             on the recording clock), LibcameraCamera (bgr8)
//   depth     Openni2Camera (devices; .oni files in real-time playback)
//   ft        AtiNetCanForceTorque and RobotousRftForceTorque on a RawCanTransport;
//             RobotiqFt300 in stream mode over a serial port, polled over Modbus TCP (at most
//             every 5 ms)
//   gripper   RobotiqGripper with ActivationPolicy::never and a 10 ms poll period: the
//             recorder only reads; it never activates or moves the fingers.
//   --tare    ATI: 100 samples on start; Robotous: the sensor's bias on start; FT 300: the
//             first sample.
//
// Lifecycle: open_device() constructs and configures; start(); the loop reads through the HAL
// interfaces; the destructor stops (if active) and cleans up. Errors: configure refused with
// invalid_argument -> UsageError (exit 2); any other configure or start failure ->
// std::runtime_error (exit 1). Both name the option, the spec and the driver's reason.
// Host code: allocates and throws. Thread safety: one thread drives the devices.
#pragma once

#include <memory>
#include <string>

#include <nlohmann/json.hpp>

#include "pliant/hal/camera.hpp"
#include "pliant/hal/clock.hpp"
#include "pliant/hal/force_torque.hpp"
#include "pliant/hal/gripper.hpp"
#include "record_device_spec.hpp"

namespace pliant::cli {

struct DeviceOpenOptions {
  bool tare = false;              ///< zero the F/T sensor at start (see the top)
  double gripper_stroke_m = 0.085;  ///< Robotiq 2F: 0.085 (2F-85) or 0.140 (2F-140), the width at full opening
};

/// One opened device. Exactly one of color(), depth(), ft(), gripper() is non-null, by role.
class RecordDevice {
 public:
  virtual ~RecordDevice() = default;
  RecordDevice(const RecordDevice&) = delete;
  RecordDevice& operator=(const RecordDevice&) = delete;

  const DeviceSpec& spec() const { return spec_; }
  /// "opencv", "libcamera", "openni2", "socketcan", "modbus".
  virtual const char* driver() const = 0;
  virtual hal::Device& device() = 0;
  virtual hal::ColorCamera* color() { return nullptr; }
  virtual hal::DepthCamera* depth() { return nullptr; }
  virtual hal::ForceTorqueSensor* ft() { return nullptr; }
  virtual hal::Gripper* gripper() { return nullptr; }

  /// inactive -> active, plus what must follow it (FT 300 tare). Throws std::runtime_error.
  void start();
  /// File-backed sources: true once every frame was delivered or dropped.
  virtual bool ended() const { return false; }
  /// Driver counters and facts for recording.json meta (JSON object).
  virtual nlohmann::json driver_info() const { return nlohmann::json::object(); }

 protected:
  explicit RecordDevice(DeviceSpec spec) : spec_(std::move(spec)) {}
  /// Called after a successful start().
  virtual void after_start() {}
  /// Stops and cleans up whatever state the device is in (for destructors).
  void shut_down() noexcept;

 private:
  DeviceSpec spec_;
};

/// Throws UsageError when the driver of `spec` is not part of this build, naming the Debian
/// package that brings it ("... install libopenni2-dev and rebuild").
void check_driver_built(const DeviceSpec& spec);

/// Constructs the device of `spec` on `clock` (which must outlive it) and configures it.
/// Throws as described at the top.
std::unique_ptr<RecordDevice> open_device(const DeviceSpec& spec, const hal::Clock& clock,
                                          const DeviceOpenOptions& options);

}  // namespace pliant::cli
