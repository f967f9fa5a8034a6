// pliant hal mocks: sample timing, sequence numbers and fault decisions shared by every mock.
//
// A mock produces sample k at capture time t_k = t_start + k x period_s (k = 0, 1, ...) with
// sequence number k + 1; it becomes available latency_s later. A read delivers the newest
// available sample not yet delivered; older ones it never delivered are lost (a sequence gap,
// counted as dropped by the device). Sample faults are decided at t_k, read faults at the time
// of the call (fault_schedule.hpp).
// Real-time safety: everything here is O(schedule size), allocation-free, noexcept.
#pragma once

#include <cstdint>

#include "pliant/hal/mock/fault_schedule.hpp"

namespace pliant::hal {

class MockStream {
 public:
  /// period_s > 0 and latency_s >= 0, both finite; supported: the FaultKind bits the device
  /// accepts. invalid_argument otherwise.
  HalStatus configure(double period_s, double latency_s, std::uint32_t supported) noexcept;
  /// Replaces the schedule; unsupported (schedule unchanged) when it uses a kind the device
  /// does not accept.
  HalStatus set_schedule(const FaultSchedule& schedule) noexcept;
  /// Adds one event (FaultSchedule::add's errors, or unsupported).
  HalStatus add_fault(const FaultEvent& event) noexcept;
  const FaultSchedule& schedule() const noexcept { return schedule_; }
  /// Starts the sample clock at t_start_s (sample 0 is captured then). Sequence numbers restart
  /// only in restart_sequence (configure); start/stop cycles continue them.
  void start(double t_start_s) noexcept;
  void restart_sequence() noexcept {
    next_index_ = 0;
    started_ = false;
  }

  /// The read fault active at now_s (disconnect, bus_off, timeout in that order), counted; ok
  /// when none.
  HalStatus read_fault(double now_s) noexcept;
  /// The newest sample available at now_s that was not yet taken: true with its index k,
  /// capture stamp t_k and sequence k + 1.
  bool take(double now_s, std::uint64_t& index, double& stamp_s, std::uint64_t& sequence) noexcept;
  /// The sample faults active at a capture stamp.
  ActiveFaults sample_faults(double stamp_s) const noexcept { return schedule_.active_at(stamp_s); }
  /// Counts one injection of `kind`.
  void count(FaultKind kind) noexcept { ++counters_.injected[static_cast<int>(kind)]; }

  const FaultCounters& fault_counters() const noexcept { return counters_; }
  void clear_fault_counters() noexcept { counters_ = FaultCounters{}; }
  double period_s() const noexcept { return period_s_; }
  double latency_s() const noexcept { return latency_s_; }
  double start_s() const noexcept { return t_start_s_; }

 private:
  FaultSchedule schedule_;
  FaultCounters counters_;
  std::uint32_t supported_ = 0;
  double period_s_ = 1;
  double latency_s_ = 0;
  double t_start_s_ = 0;
  std::uint64_t next_index_ = 0;  ///< the first index not yet taken
  bool started_ = false;
};

}  // namespace pliant::hal
