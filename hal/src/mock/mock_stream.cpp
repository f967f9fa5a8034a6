#include "pliant/hal/mock/mock_stream.hpp"

#include <cmath>

namespace pliant::hal {

HalStatus MockStream::configure(double period_s, double latency_s, std::uint32_t supported) noexcept {
  if (!(std::isfinite(period_s) && period_s > 0) || !(std::isfinite(latency_s) && latency_s >= 0)) {
    return HalStatus::invalid_argument;
  }
  if ((schedule_.kinds() & ~supported) != 0) return HalStatus::unsupported;
  period_s_ = period_s;
  latency_s_ = latency_s;
  supported_ = supported;
  restart_sequence();
  return HalStatus::ok;
}

HalStatus MockStream::set_schedule(const FaultSchedule& schedule) noexcept {
  if (supported_ != 0 && (schedule.kinds() & ~supported_) != 0) return HalStatus::unsupported;
  schedule_ = schedule;
  return HalStatus::ok;
}

HalStatus MockStream::add_fault(const FaultEvent& event) noexcept {
  const int kind = static_cast<int>(event.kind);
  if (kind >= 0 && kind < kFaultKindCount && supported_ != 0 && (fault_bit(event.kind) & supported_) == 0) {
    return HalStatus::unsupported;
  }
  return schedule_.add(event);
}

void MockStream::start(double t_start_s) noexcept {
  // Sequence numbers continue across stop/start: the capture clock restarts at the next index.
  t_start_s_ = t_start_s - static_cast<double>(next_index_) * period_s_;
  started_ = true;
}

HalStatus MockStream::read_fault(double now_s) noexcept { return apply_read_fault(schedule_, now_s, counters_); }

bool MockStream::take(double now_s, std::uint64_t& index, double& stamp_s, std::uint64_t& sequence) noexcept {
  if (!started_ || !std::isfinite(now_s)) return false;
  // The newest capture whose data is available; a little slack for stepped clocks' rounding.
  const double newest = std::floor((now_s - latency_s_ - t_start_s_) / period_s_ + 1e-6);
  // Indices past 2^53 (a clock years away from the start) are refused rather than cast.
  if (!(newest >= 0) || newest > 9.0e15 || newest < static_cast<double>(next_index_)) return false;
  index = static_cast<std::uint64_t>(newest);
  next_index_ = index + 1;
  stamp_s = t_start_s_ + static_cast<double>(index) * period_s_;
  sequence = index + 1;
  return true;
}

}  // namespace pliant::hal
