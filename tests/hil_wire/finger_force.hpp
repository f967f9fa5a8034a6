// The grip force of a gripper that senses none, from the force sensor in its finger.
//
// A Robotiq reports no grip force (force_n NaN; its motor current comes in 10 mA counts, about
// 3 N here). In the wire rig the ATI sensor sits in the finger, as the HAL HIL's F/T mock does,
// so its force along the squeeze axis is the grip force. Two HAL decorators carry it over:
//   RecordingForceTorque  reads the sensor for its caller and keeps the last delivered reading;
//   FingerForceGripper    reads the gripper and sets force_n to that reading's axis `axis`
//                         (NaN until the sensor delivered one).
// The supervisor reads the gripper before the sensor, so the force it sees with a gripper sample
// is the sensor's sample of the previous cycle (one control period older); every fault of the
// sensor still reaches the guard through the sensor's own sample, in the cycle it happens.
// Lifecycle: each decorator forwards configure/start/stop/cleanup to the device it wraps.
// Real-time safety: read and write are the wrapped device's plus O(1); no allocation.
#pragma once

#include "pliant/hal/force_torque.hpp"
#include "pliant/hal/gripper.hpp"

namespace pliant::hil {

/// A HAL device of kind Base that wraps another of the same kind: the lifecycle is forwarded.
template <typename Base>
class Decorator : public Base {
 protected:
  explicit Decorator(Base& inner) noexcept : inner_(inner) {}
  hal::HalStatus on_configure() override { return inner_.configure(); }
  hal::HalStatus on_start() noexcept override { return inner_.start(); }
  hal::HalStatus on_stop() noexcept override { return inner_.stop(); }
  hal::HalStatus on_cleanup() noexcept override { return inner_.cleanup(); }

  Base& inner_;
};

class RecordingForceTorque final : public Decorator<hal::ForceTorqueSensor> {
 public:
  explicit RecordingForceTorque(hal::ForceTorqueSensor& sensor) noexcept : Decorator(sensor) {}
  /// The last reading delivered (has_reading() false before the first).
  const hal::WrenchReading& last() const noexcept { return last_; }
  bool has_reading() const noexcept { return has_reading_; }

 protected:
  hal::HalStatus on_read(hal::WrenchReading& out) noexcept override;

 private:
  hal::WrenchReading last_;
  bool has_reading_ = false;
};

class FingerForceGripper final : public Decorator<hal::Gripper> {
 public:
  /// `axis`: 0..2, the sensor's force axis along the squeeze.
  FingerForceGripper(hal::Gripper& gripper, const RecordingForceTorque& finger, int axis) noexcept
      : Decorator(gripper), finger_(finger), axis_(axis) {}
  hal::GripperLimits limits() const noexcept override { return inner_.limits(); }

 protected:
  hal::HalStatus on_read(hal::GripperReading& out) noexcept override;
  hal::HalStatus on_write(const hal::GripperCommand& command) noexcept override { return inner_.write(command); }

 private:
  const RecordingForceTorque& finger_;
  int axis_;
};

}  // namespace pliant::hil
