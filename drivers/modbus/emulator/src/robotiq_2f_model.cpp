#include "pliant/drivers/modbus/emulator/robotiq_2f_model.hpp"

#include <algorithm>
#include <cmath>

namespace pliant::drivers::modbus {
namespace r2f = robotiq2f;

Robotiq2fModel::Robotiq2fModel(const Robotiq2fModelConfig& config) noexcept
    : config_(config), width_m_(config.scaling.stroke_m) {}

bool Robotiq2fModel::has_object() const noexcept {
  if (object_ != nullptr) return true;
  return std::isfinite(config_.object_width_m) && config_.object_stiffness_n_per_m > 0;
}

// Width at which the squeeze force reaches the commanded force limit (NaN: never).
double Robotiq2fModel::contact_stop_width() const noexcept {
  const double limit_n = r2f::byte_to_force(command_.force, config_.scaling);
  if (object_ != nullptr) return object_->width_at_force(limit_n);
  if (std::isinf(config_.object_stiffness_n_per_m)) return config_.object_width_m;
  return config_.object_width_m - limit_n / config_.object_stiffness_n_per_m;
}

void Robotiq2fModel::write_command(const r2f::Command& command) noexcept {
  const r2f::Command previous = command_;
  command_ = command;
  const bool act = (command.action & r2f::kActionActivate) != 0;
  const bool go = (command.action & r2f::kActionGoTo) != 0;
  if (!act) {
    gsta_ = r2f::kStaReset;
    gobj_ = r2f::kObjMoving;
    moving_ = false;
    activation_elapsed_s_ = 0;
    minor_fault_ = go ? r2f::kFaultActivationBitNotSet : 0;
    return;
  }
  if (gsta_ == r2f::kStaReset) {
    gsta_ = r2f::kStaActivating;
    activation_elapsed_s_ = 0;
  }
  if (gsta_ != r2f::kStaActivated) {
    minor_fault_ = go ? r2f::kFaultActionDelayed : 0;
    return;
  }
  minor_fault_ = 0;
  if (!go) {
    moving_ = false;
    return;
  }
  const bool rising = (previous.action & r2f::kActionGoTo) == 0;
  const bool changed =
      previous.position != command.position || previous.speed != command.speed || previous.force != command.force;
  if (rising || changed) {
    moving_ = true;
    gobj_ = r2f::kObjMoving;
  }
}

void Robotiq2fModel::step(double dt_s) noexcept {
  if (!(dt_s >= 0)) return;
  if (gsta_ == r2f::kStaActivating) {
    activation_elapsed_s_ += dt_s;
    if (activation_elapsed_s_ >= config_.activation_time_s) {
      gsta_ = r2f::kStaActivated;
      width_m_ = config_.scaling.stroke_m;
      gobj_ = r2f::kObjMoving;
      moving_ = false;
    }
    return;
  }
  if (fault_ != 0 || !moving_) {
    moving_ = moving_ && fault_ == 0;
    return;
  }
  const double target = r2f::position_to_width(command_.position, config_.scaling);
  const double speed = r2f::byte_to_speed(command_.speed, config_.scaling);
  if (target < width_m_) {
    // Closing: stop at the target or where the squeeze reaches the force limit, whichever first.
    double stop = target;
    bool contact = false;
    if (has_object()) {
      const double contact_w = contact_stop_width();
      if (contact_w >= target) {
        stop = contact_w;
        contact = true;
      }
    }
    if (width_m_ <= stop) {  // already squeezed at least that much: the limit holds at once
      moving_ = false;
      gobj_ = contact ? r2f::kObjContactClosing : r2f::kObjAtPosition;
      return;
    }
    width_m_ = std::max(width_m_ - speed * dt_s, stop);
    if (width_m_ <= stop) {
      width_m_ = stop;
      moving_ = false;
      gobj_ = contact ? r2f::kObjContactClosing : r2f::kObjAtPosition;
    }
    return;
  }
  width_m_ = std::min(width_m_ + speed * dt_s, target);
  if (width_m_ >= target) {
    width_m_ = target;
    moving_ = false;
    gobj_ = r2f::kObjAtPosition;
  }
}

double Robotiq2fModel::grip_force_n() const noexcept {
  if (object_ != nullptr) return std::max(0.0, object_->force_n(width_m_));
  if (!has_object() || width_m_ > config_.object_width_m) return 0;
  if (std::isinf(config_.object_stiffness_n_per_m)) {
    const bool holding =
        gsta_ == r2f::kStaActivated && (command_.action & r2f::kActionGoTo) != 0 && gobj_ == r2f::kObjContactClosing;
    return holding ? r2f::byte_to_force(command_.force, config_.scaling) : 0.0;
  }
  return config_.object_stiffness_n_per_m * (config_.object_width_m - width_m_);
}

double Robotiq2fModel::current_a() const noexcept {
  return (moving_ ? config_.moving_current_a : 0.0) + config_.current_per_newton_a * grip_force_n();
}

r2f::Status Robotiq2fModel::status() const noexcept {
  r2f::Status s;
  s.gact = gsta_ == r2f::kStaActivated ? 1 : 0;
  s.ggto = (command_.action & r2f::kActionGoTo) != 0 ? 1 : 0;
  s.gsta = gsta_;
  s.gobj = s.ggto == 1 && gsta_ == r2f::kStaActivated ? gobj_ : r2f::kObjMoving;
  const std::uint8_t fault = fault_ != 0 ? fault_ : minor_fault_;
  s.gflt = static_cast<std::uint8_t>(fault & 0x0fu);
  s.kflt = static_cast<std::uint8_t>(fault >> 4);
  s.position_request = command_.position;
  s.position = r2f::width_to_position(width_m_, config_.scaling);
  const double counts = std::round(current_a() / 0.01);
  s.current = counts >= 255 ? std::uint8_t{255} : counts <= 0 ? std::uint8_t{0} : static_cast<std::uint8_t>(counts);
  return s;
}

void Robotiq2fModel::status_registers(std::uint16_t out[r2f::kRegisterCount]) const noexcept {
  r2f::encode_status(status(), out);
}

void Robotiq2fModel::set_object(double width_m, double stiffness_n_per_m) noexcept {
  config_.object_width_m = width_m;
  config_.object_stiffness_n_per_m = stiffness_n_per_m;
}

void Robotiq2fModel::set_fault(std::uint8_t fault_byte) noexcept {
  fault_ = fault_byte;
  if (fault_ != 0) moving_ = false;
}

void Robotiq2fModel::set_width(double width_m) noexcept {
  if (std::isnan(width_m)) return;
  width_m_ = std::clamp(width_m, 0.0, config_.scaling.stroke_m);
  moving_ = false;
}

}  // namespace pliant::drivers::modbus
