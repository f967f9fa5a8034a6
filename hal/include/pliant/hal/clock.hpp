// pliant hal: the one monotonic clock every sample is stamped with.
//
// Every device takes a `const Clock&` at construction and stamps each sample with now_s() of
// that clock (capture time where the device knows it, else the time it was read). The grasp
// guard's `now_s` must come from the same clock, so that sample ages are meaningful.
//
//   SteadyClock  - std::chrono::steady_clock in seconds: real-time runs.
//   ManualClock  - time moves only when the caller advances it: stepped tests and HIL loops,
//                  reproducible to the bit.
//
// Units: seconds, monotonic (never decreases), origin unspecified (compare stamps, not dates).
// Real-time safety: now_s() is O(1), allocation-free and noexcept for both clocks.
// Thread safety: SteadyClock may be read from any thread. ManualClock is not synchronised:
// advance it from the thread that runs the loop.
#pragma once

#include "pliant/hal/status.hpp"

namespace pliant::hal {

class Clock {
 public:
  virtual ~Clock() = default;
  /// Monotonic time, seconds.
  virtual double now_s() const noexcept = 0;

 protected:
  Clock() = default;
  Clock(const Clock&) = default;
  Clock& operator=(const Clock&) = default;
};

/// std::chrono::steady_clock, seconds since its (unspecified) epoch.
class SteadyClock final : public Clock {
 public:
  double now_s() const noexcept override;
};

/// A clock that moves only when told to. Starts at `start_s` (finite; default 0).
class ManualClock final : public Clock {
 public:
  explicit ManualClock(double start_s = 0) noexcept;
  double now_s() const noexcept override { return now_s_; }
  /// Moves time forward by dt_s (finite, >= 0). invalid_argument otherwise (time unchanged).
  HalStatus advance(double dt_s) noexcept;
  /// Sets time to t_s (finite, >= now). invalid_argument otherwise: the clock never goes back.
  HalStatus set(double t_s) noexcept;

 private:
  double now_s_ = 0;
};

}  // namespace pliant::hal
