#include "pliant/drivers/modbus/robotiq_gripper.hpp"

#include <cmath>

namespace pliant::drivers::modbus {
namespace {

using hal::HalStatus;
namespace r2f = robotiq2f;

bool finite_non_negative(double v) noexcept { return std::isfinite(v) && v >= 0; }
bool finite_positive(double v) noexcept { return std::isfinite(v) && v > 0; }

}  // namespace

RobotiqGripper::RobotiqGripper(const hal::Clock& clock, const RobotiqGripperConfig& config)
    : clock_(clock), config_(config), link_(clock) {}

hal::GripperLimits RobotiqGripper::limits() const noexcept {
  hal::GripperLimits l;
  l.min_width_m = 0;
  l.max_width_m = config_.scaling.stroke_m;
  l.max_speed_m_per_s = config_.scaling.max_speed_m_per_s;
  l.min_force_n = config_.scaling.min_force_n;
  l.max_force_n = config_.scaling.max_force_n;
  return l;
}

HalStatus RobotiqGripper::on_configure() {
  const RobotiqGripperConfig& c = config_;
  if (r2f::validate(c.scaling) != HalStatus::ok || !finite_non_negative(c.reset_hold_s) ||
      !finite_positive(c.activation_timeout_s) || !finite_non_negative(c.min_poll_period_s) ||
      !finite_positive(c.open_force_n)) {
    return HalStatus::invalid_argument;
  }
  table_ = c.status_read == StatusRead::holding_registers ? RegisterTable::holding : RegisterTable::input;
  table_settled_ = c.status_read != StatusRead::auto_detect;
  phase_ = Phase::idle;
  polled_ = false;
  sequence_ = 0;
  last_status_ = r2f::Status{};
  last_command_ = r2f::Command{};
  counters_ = RobotiqGripperCounters{};
  return link_.open(c.link);
}

HalStatus RobotiqGripper::on_start() noexcept {
  r2f::Status status;
  const HalStatus s = poll_status(status);
  if (s != HalStatus::ok) return s;
  last_status_ = status;
  phase_ = Phase::idle;
  switch (config_.activation) {
    case ActivationPolicy::never: return HalStatus::ok;
    case ActivationPolicy::if_needed:
      if (r2f::is_activated(status)) return HalStatus::ok;
      break;
    case ActivationPolicy::always: break;
  }
  return begin_activation(clock_.now_s());
}

HalStatus RobotiqGripper::on_cleanup() noexcept {
  link_.close();
  return HalStatus::ok;
}

HalStatus RobotiqGripper::reactivate() noexcept {
  if (state() != hal::LifecycleState::active) return HalStatus::wrong_state;
  return begin_activation(clock_.now_s());
}

HalStatus RobotiqGripper::poll_status(r2f::Status& out) noexcept {
  std::uint16_t registers[r2f::kRegisterCount] = {0, 0, 0};
  HalStatus s = link_.read_registers(table_, r2f::kStatusRegister, r2f::kRegisterCount, registers);
  if (s == HalStatus::unsupported && !table_settled_ && table_ == RegisterTable::input) {
    // The gripper rejected FC04 with "illegal function": an older firmware; use FC03 for good.
    table_ = RegisterTable::holding;
    table_settled_ = true;
    ++counters_.fc03_fallbacks;
    s = link_.read_registers(table_, r2f::kStatusRegister, r2f::kRegisterCount, registers);
  }
  if (s == HalStatus::ok) table_settled_ = true;
  if (s == HalStatus::unsupported) return HalStatus::io_error;
  if (s != HalStatus::ok) return s;
  out = r2f::decode_status(registers);
  return HalStatus::ok;
}

HalStatus RobotiqGripper::send(const r2f::Command& command) noexcept {
  std::uint16_t registers[r2f::kRegisterCount] = {0, 0, 0};
  r2f::encode_command(command, registers);
  HalStatus s = link_.write_registers(r2f::kCommandRegister, r2f::kRegisterCount, registers);
  if (s == HalStatus::unsupported) s = HalStatus::io_error;
  if (s == HalStatus::ok) last_command_ = command;
  return s;
}

HalStatus RobotiqGripper::begin_activation(double now_s) noexcept {
  ++counters_.activations;
  const HalStatus s = send(r2f::Command{});  // reset: rACT = 0 clears the activation and faults
  if (s != HalStatus::ok) return s;
  phase_ = Phase::reset_sent;
  phase_since_s_ = now_s;
  return HalStatus::ok;
}

HalStatus RobotiqGripper::advance_activation(double now_s) noexcept {
  switch (phase_) {
    case Phase::idle: return HalStatus::ok;
    case Phase::reset_sent: {
      if (now_s - phase_since_s_ < config_.reset_hold_s) return HalStatus::ok;
      r2f::Command activate;
      activate.action = r2f::kActionActivate;
      const HalStatus s = send(activate);
      if (s != HalStatus::ok) return s;
      phase_ = Phase::activate_sent;
      phase_since_s_ = now_s;
      return HalStatus::ok;
    }
    case Phase::activate_sent:
      if (r2f::is_activated(last_status_)) {
        phase_ = Phase::idle;
        return HalStatus::ok;
      }
      if (now_s - phase_since_s_ < config_.activation_timeout_s) return HalStatus::ok;
      ++counters_.activation_retries;
      return begin_activation(now_s);
  }
  return HalStatus::ok;
}

HalStatus RobotiqGripper::on_read(hal::GripperReading& out) noexcept {
  const double now = clock_.now_s();
  if (polled_ && config_.min_poll_period_s > 0 && now - last_poll_s_ < config_.min_poll_period_s) {
    ++counters_.polls_skipped;
    return HalStatus::no_data;
  }
  polled_ = true;
  last_poll_s_ = now;
  r2f::Status status;
  HalStatus s = poll_status(status);
  if (s != HalStatus::ok) return s;
  last_status_ = status;
  const double stamp = clock_.now_s();
  if (phase_ != Phase::idle) {
    s = advance_activation(stamp);
    if (s != HalStatus::ok) return s;
  }
  hal::GripperReading r;
  r2f::to_reading(status, config_.scaling, r);
  r.header.stamp_s = stamp;
  r.header.sequence = ++sequence_;
  out = r;
  return HalStatus::ok;
}

HalStatus RobotiqGripper::on_write(const hal::GripperCommand& command) noexcept {
  if (phase_ != Phase::idle || !r2f::is_activated(last_status_)) return HalStatus::wrong_state;
  const r2f::Scaling& sc = config_.scaling;
  r2f::Command target;
  target.action = static_cast<std::uint8_t>(r2f::kActionActivate | r2f::kActionGoTo);
  switch (command.kind) {
    case hal::GripperCommandKind::stop: {
      r2f::Command hold = last_command_;
      hold.action = r2f::kActionActivate;
      return send(hold);
    }
    case hal::GripperCommandKind::move:
      target.position = r2f::width_to_position(command.width_m, sc);
      target.speed = r2f::speed_to_byte(command.speed_m_per_s, sc);
      target.force = r2f::force_to_byte(command.force_n, sc);
      break;
    case hal::GripperCommandKind::open:
      target.position = sc.open_byte;
      target.speed = r2f::speed_to_byte(command.speed_m_per_s, sc);
      target.force = r2f::force_to_byte(config_.open_force_n, sc);
      break;
    default: return HalStatus::invalid_argument;
  }
  if ((last_command_.action & r2f::kActionGoTo) != 0) {
    r2f::Command rearm = target;
    rearm.action = r2f::kActionActivate;
    const HalStatus s = send(rearm);
    if (s != HalStatus::ok) return s;
  }
  return send(target);
}

}  // namespace pliant::drivers::modbus
