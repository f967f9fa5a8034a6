#include "pliant/hal/gripper.hpp"

#include <algorithm>
#include <cmath>

namespace pliant::hal {

HalStatus Gripper::read(GripperReading& out) noexcept {
  if (!admit()) return HalStatus::wrong_state;
  GripperReading sample;
  const HalStatus status = on_read(sample);
  account_read(status, sample.header);
  if (status == HalStatus::ok) out = sample;
  return status;
}

HalStatus Gripper::write(const GripperCommand& command) noexcept {
  if (!admit()) return HalStatus::wrong_state;
  const GripperLimits l = limits();
  GripperCommand clamped = command;
  bool valid = true;
  switch (command.kind) {
    case GripperCommandKind::move:
      valid = std::isfinite(command.width_m) && std::isfinite(command.speed_m_per_s) && command.speed_m_per_s > 0 &&
              std::isfinite(command.force_n) && command.force_n > 0;
      if (valid) {
        clamped.width_m = std::clamp(command.width_m, l.min_width_m, l.max_width_m);
        clamped.speed_m_per_s = std::min(command.speed_m_per_s, l.max_speed_m_per_s);
        clamped.force_n = std::clamp(command.force_n, l.min_force_n, l.max_force_n);
      }
      break;
    case GripperCommandKind::open:
      valid = std::isfinite(command.speed_m_per_s) && command.speed_m_per_s > 0;
      if (valid) {
        clamped.width_m = l.max_width_m;
        clamped.speed_m_per_s = std::min(command.speed_m_per_s, l.max_speed_m_per_s);
      }
      break;
    case GripperCommandKind::stop: break;
    default: valid = false; break;
  }
  const HalStatus status = valid ? on_write(clamped) : HalStatus::invalid_argument;
  account_write(status);
  return status;
}

HalStatus Gripper::move_to(double width_m, double speed_m_per_s, double force_n) noexcept {
  GripperCommand command;
  command.kind = GripperCommandKind::move;
  command.width_m = width_m;
  command.speed_m_per_s = speed_m_per_s;
  command.force_n = force_n;
  return write(command);
}

HalStatus Gripper::freeze() noexcept {
  GripperCommand command;
  command.kind = GripperCommandKind::stop;
  return write(command);
}

HalStatus Gripper::open(double speed_m_per_s) noexcept {
  GripperCommand command;
  command.kind = GripperCommandKind::open;
  command.speed_m_per_s = speed_m_per_s;
  return write(command);
}

}  // namespace pliant::hal
