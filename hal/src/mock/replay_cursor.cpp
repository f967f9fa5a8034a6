#include "pliant/hal/mock/replay_cursor.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "sample_faults.hpp"

namespace pliant::hal {

using detail::SampleFate;

HalStatus ReplayCursor::configure(const RecordedChannel& channel, const ReplayTiming& timing, std::uint32_t supported,
                                  std::uint32_t default_fault_bits) {
  const int n = channel.count();
  if (n == 0 || channel.width <= 0 ||
      channel.values.size() != static_cast<std::size_t>(n) * static_cast<std::size_t>(channel.width)) {
    return HalStatus::invalid_argument;
  }
  for (int k = 0; k < n; ++k) {
    const double t = channel.t_s[static_cast<std::size_t>(k)];
    if (!std::isfinite(t) || (k > 0 && !(t > channel.t_s[static_cast<std::size_t>(k - 1)]))) {
      return HalStatus::invalid_argument;
    }
  }
  if (!(std::isfinite(timing.speed) && timing.speed > 0) ||
      (timing.mode != ReplayMode::realtime && timing.mode != ReplayMode::stepped)) {
    return HalStatus::invalid_argument;
  }
  if ((schedule_.kinds() & ~supported) != 0) return HalStatus::unsupported;
  channel_ = &channel;
  timing_ = timing;
  supported_ = supported;
  default_fault_bits_ = default_fault_bits;
  row_.assign(static_cast<std::size_t>(channel.width), std::numeric_limits<double>::quiet_NaN());
  counters_ = FaultCounters{};
  next_ = 0;
  last_index_ = -1;
  started_ = false;
  has_last_ = false;
  return HalStatus::ok;
}

HalStatus ReplayCursor::set_schedule(const FaultSchedule& schedule) noexcept {
  if (supported_ != 0 && (schedule.kinds() & ~supported_) != 0) return HalStatus::unsupported;
  schedule_ = schedule;
  return HalStatus::ok;
}

HalStatus ReplayCursor::add_fault(const FaultEvent& event) noexcept {
  const int kind = static_cast<int>(event.kind);
  if (kind >= 0 && kind < kFaultKindCount && supported_ != 0 && (fault_bit(event.kind) & supported_) == 0) {
    return HalStatus::unsupported;
  }
  return schedule_.add(event);
}

void ReplayCursor::start(double now_s) noexcept {
  if (channel_ == nullptr) return;
  const auto& t = channel_->t_s;
  const double first = t.front();
  const double next_t = next_ < channel_->count() ? t[static_cast<std::size_t>(next_)] : t.back();
  anchor_s_ = now_s - (next_t - first) / timing_.speed;
  started_ = true;
}

double ReplayCursor::stamp_of(int index) const noexcept {
  return anchor_s_ + (channel_->t_s[static_cast<std::size_t>(index)] - channel_->t_s.front()) / timing_.speed;
}

double ReplayCursor::next_due_s() const noexcept {
  if (!started_ || channel_ == nullptr || finished()) return std::numeric_limits<double>::infinity();
  return stamp_of(next_);
}

HalStatus ReplayCursor::read_fault(double now_s) noexcept { return apply_read_fault(schedule_, now_s, counters_); }

bool ReplayCursor::take(double now_s, ReplaySample& out) noexcept {
  if (!started_ || channel_ == nullptr || finished()) return false;
  int index = next_;
  if (timing_.mode == ReplayMode::realtime) {
    if (!std::isfinite(now_s) || stamp_of(next_) > now_s) return false;
    // The newest due sample: binary search over the recorded times.
    const double recorded_now = channel_->t_s.front() + (now_s - anchor_s_) * timing_.speed;
    const auto begin = channel_->t_s.begin() + next_;
    const auto after = std::upper_bound(begin, channel_->t_s.end(), recorded_now);
    index = std::max(next_, static_cast<int>(after - channel_->t_s.begin()) - 1);
  }
  next_ = index + 1;
  const double stamp = stamp_of(index);
  const ActiveFaults f = schedule_.active_at(stamp);
  const SampleFate fate = detail::sample_fate(f, has_last_, *this);
  if (fate == SampleFate::dropped) return false;
  ReplaySample s;
  s.index = index;
  s.sequence = static_cast<std::uint64_t>(index) + 1;
  s.faults = f;
  if (fate == SampleFate::repeat_previous) {
    s.stamp_s = last_stamp_s_;
    s.status_bits = last_status_;
  } else {
    if (fate == SampleFate::fresh) {  // previous_values: row_ keeps the previous values
      const double* src = channel_->values.data() + static_cast<std::size_t>(index) * row_.size();
      std::copy(src, src + row_.size(), row_.begin());
    }
    s.stamp_s = stamp;
    if (detail::take_fault(f, FaultKind::nan, *this)) {
      std::fill(row_.begin(), row_.end(), std::numeric_limits<double>::quiet_NaN());
    }
    detail::apply_stamp_and_status_faults(f, default_fault_bits_, *this, s.stamp_s, s.status_bits);
  }
  s.values = row_.data();
  last_index_ = index;
  has_last_ = true;
  last_stamp_s_ = s.stamp_s;
  last_status_ = s.status_bits;
  out = s;
  return true;
}

}  // namespace pliant::hal
