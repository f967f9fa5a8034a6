// The categories' read wrappers: lifecycle check, then the device's hook, then the counters.
#include "pliant/hal/camera.hpp"
#include "pliant/hal/force_torque.hpp"

namespace pliant::hal {

HalStatus ForceTorqueSensor::read(WrenchReading& out) noexcept {
  if (!admit()) return HalStatus::wrong_state;
  WrenchReading sample;
  const HalStatus status = on_read(sample);
  account_read(status, sample.header);
  if (status == HalStatus::ok) out = sample;
  return status;
}

HalStatus ColorCamera::read(ColorFrame& out) noexcept {
  if (!admit()) return HalStatus::wrong_state;
  ColorFrame frame;
  const HalStatus status = on_read(frame);
  account_read(status, frame.header);
  if (status == HalStatus::ok) out = frame;
  return status;
}

HalStatus DepthCamera::read(DepthFrame& out) noexcept {
  if (!admit()) return HalStatus::wrong_state;
  DepthFrame frame;
  const HalStatus status = on_read(frame);
  account_read(status, frame.header);
  if (status == HalStatus::ok) out = frame;
  return status;
}

HalStatus ParticleObserver::read(ParticleFrame& out) noexcept {
  if (!admit()) return HalStatus::wrong_state;
  ParticleFrame frame;
  const HalStatus status = on_read(frame);
  account_read(status, frame.header);
  if (status == HalStatus::ok) out = frame;
  return status;
}

}  // namespace pliant::hal
