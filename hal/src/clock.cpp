#include "pliant/hal/clock.hpp"

#include <chrono>
#include <cmath>

namespace pliant::hal {

double SteadyClock::now_s() const noexcept {
  const auto since = std::chrono::steady_clock::now().time_since_epoch();
  return std::chrono::duration<double>(since).count();
}

ManualClock::ManualClock(double start_s) noexcept : now_s_(std::isfinite(start_s) ? start_s : 0.0) {}

HalStatus ManualClock::advance(double dt_s) noexcept {
  if (!std::isfinite(dt_s) || dt_s < 0) return HalStatus::invalid_argument;
  now_s_ += dt_s;
  return HalStatus::ok;
}

HalStatus ManualClock::set(double t_s) noexcept {
  if (!std::isfinite(t_s) || t_s < now_s_) return HalStatus::invalid_argument;
  now_s_ = t_s;
  return HalStatus::ok;
}

}  // namespace pliant::hal
