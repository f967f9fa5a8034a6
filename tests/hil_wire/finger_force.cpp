#include "finger_force.hpp"

#include <limits>

namespace pliant::hil {

hal::HalStatus RecordingForceTorque::on_read(hal::WrenchReading& out) noexcept {
  const hal::HalStatus s = inner_.read(out);
  if (s == hal::HalStatus::ok) {
    last_ = out;
    has_reading_ = true;
  }
  return s;
}

hal::HalStatus FingerForceGripper::on_read(hal::GripperReading& out) noexcept {
  const hal::HalStatus s = inner_.read(out);
  if (s == hal::HalStatus::ok) {
    out.force_n = finger_.has_reading() ? finger_.last().wrench[axis_] : std::numeric_limits<double>::quiet_NaN();
  }
  return s;
}

}  // namespace pliant::hil
