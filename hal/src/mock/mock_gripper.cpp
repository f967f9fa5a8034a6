#include "pliant/hal/mock/mock_gripper.hpp"

#include <cmath>
#include <limits>

#include "sample_faults.hpp"

namespace pliant::hal {

using detail::SampleFate;

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

bool non_negative(double v) { return std::isfinite(v) && v >= 0; }

}  // namespace

GripperLimits MockGripper::limits() const noexcept {
  GripperLimits l;
  l.min_width_m = plant_.configured() ? plant_.min_width_m() : 0.0;
  l.max_width_m = plant_.configured() ? plant_.max_width_m() : 0.0;
  l.max_speed_m_per_s = config_.max_speed_m_per_s;
  l.min_force_n = config_.min_force_n;
  l.max_force_n = config_.max_force_n;
  return l;
}

HalStatus MockGripper::on_configure() {
  const MockGripperConfig& c = config_;
  if (!plant_.configured()) return HalStatus::invalid_argument;
  if (!non_negative(c.width_noise_m) || !non_negative(c.force_noise_n) || !non_negative(c.current_noise_a) ||
      !(std::isfinite(c.current_gain_n_per_a) && c.current_gain_n_per_a > 0) || !std::isfinite(c.current_offset_a) ||
      !non_negative(c.min_force_n) || !(std::isfinite(c.max_force_n) && c.max_force_n >= c.min_force_n) ||
      !(std::isfinite(c.max_speed_m_per_s) && c.max_speed_m_per_s > 0)) {
    return HalStatus::invalid_argument;
  }
  const HalStatus s = stream_.configure(c.period_s, 0.0, kGripperFaults);
  if (s != HalStatus::ok) return s;
  stream_.clear_fault_counters();
  rng_.seed(c.seed);
  has_last_ = false;
  faulted_ = false;
  return HalStatus::ok;
}

HalStatus MockGripper::on_start() noexcept {
  stream_.start(clock_.now_s());
  return HalStatus::ok;
}

bool MockGripper::update_actuator_fault(double now_s) noexcept {
  const bool active = stream_.sample_faults(now_s).has(FaultKind::fault_bits);
  if (active && !faulted_) plant_.command_stop();
  plant_.set_actuator_fault(active);
  faulted_ = active;
  return active;
}

HalStatus MockGripper::on_read(GripperReading& out) noexcept {
  plant_.sync();
  const double now = clock_.now_s();
  update_actuator_fault(now);
  const HalStatus link = stream_.read_fault(now);
  if (link != HalStatus::ok) return link;
  std::uint64_t index = 0, sequence = 0;
  double stamp = 0;
  if (!stream_.take(now, index, stamp, sequence)) return HalStatus::no_data;
  const ActiveFaults f = stream_.sample_faults(stamp);
  const SampleFate fate = detail::sample_fate(f, has_last_, stream_);
  if (fate == SampleFate::dropped) return HalStatus::no_data;
  GripperReading r;
  if (fate == SampleFate::fresh) {
    const double force = plant_.grip_force_n();
    r.width_m = plant_.width_m() + config_.width_noise_m * normal_(rng_);
    r.force_n = force + config_.force_noise_n * normal_(rng_);
    r.current_a =
        config_.current_offset_a + force / config_.current_gain_n_per_a + config_.current_noise_a * normal_(rng_);
    r.target_width_m = plant_.target_width_m();
    std::uint32_t bits = kGripperActivated;
    if (plant_.moving()) bits |= kGripperMoving;
    if (plant_.object_detected()) bits |= kGripperObjectDetected;
    if (!plant_.moving() && plant_.width_m() == plant_.target_width_m()) bits |= kGripperAtTarget;
    r.header.status_bits = bits;
  } else {
    r = last_;  // freeze_stamp: the whole previous reading; freeze_data: its values and status
  }
  if (fate != SampleFate::repeat_previous) {
    r.header.stamp_s = stamp;
    if (detail::take_fault(f, FaultKind::nan, stream_)) r.width_m = r.force_n = r.current_a = kNaN;
    const std::uint32_t fault_word = std::uint32_t{config_.fault_code} << kGripperFaultCodeShift;
    detail::apply_stamp_and_status_faults(f, fault_word, stream_, r.header.stamp_s, r.header.status_bits);
  }
  r.header.sequence = sequence;
  last_ = r;
  has_last_ = true;
  out = r;
  return HalStatus::ok;
}

HalStatus MockGripper::on_write(const GripperCommand& command) noexcept {
  plant_.sync();
  const double now = clock_.now_s();
  const bool faulted = update_actuator_fault(now);
  const HalStatus link = stream_.read_fault(now);
  if (link != HalStatus::ok) return link;
  if (faulted) return HalStatus::device_fault;
  switch (command.kind) {
    case GripperCommandKind::move: plant_.command_move(command.width_m, command.speed_m_per_s, command.force_n); break;
    case GripperCommandKind::stop: plant_.command_stop(); break;
    case GripperCommandKind::open: plant_.command_open(command.speed_m_per_s); break;
    default: return HalStatus::invalid_argument;
  }
  return HalStatus::ok;
}

}  // namespace pliant::hal
