// pliant hal mocks (private to hal/src/mock): the sample-fault preamble every mock shares.
//
// A sample's sample faults (fault_schedule.hpp) act in this order of precedence:
//   drop          not delivered;
//   freeze_stamp  the previous delivered sample again, stamp and status word included;
//   freeze_data   the previous delivered values under the new stamp;
// the two freeze kinds only when there is a previous sample to repeat (else the sample is fresh).
// On a sample that is not a repeat, nan (the device's notion of "no values"), stamp_jump and
// fault_bits then apply. Each helper counts, once per sample, the kinds it applies.
//
// Counter: anything with `void count(FaultKind) noexcept` (MockStream, ReplayCursor, or a
// FaultCounterSink over a device's own FaultCounters).
// Real-time safety: header-only templates, noexcept, no allocation, no exceptions or RTTI.
#pragma once

#include <cmath>
#include <cstdint>

#include "pliant/hal/mock/fault_schedule.hpp"

namespace pliant::hal::detail {

/// Where a sample's values come from, after drop, freeze_stamp and freeze_data.
enum class SampleFate : std::uint8_t {
  dropped,          ///< drop: not delivered (its sequence number becomes a gap)
  repeat_previous,  ///< freeze_stamp: the previous delivered sample, stamp and status included
  previous_values,  ///< freeze_data: the previous delivered values, new stamp
  fresh,            ///< new values
};

/// A Counter over a FaultCounters the device keeps itself.
struct FaultCounterSink {
  FaultCounters& counters;
  void count(FaultKind kind) noexcept { ++counters.injected[static_cast<int>(kind)]; }
};

/// True, and counted, when `kind` is active in `faults`.
template <class Counter>
bool take_fault(const ActiveFaults& faults, FaultKind kind, Counter& counter) noexcept {
  if (!faults.has(kind)) return false;
  counter.count(kind);
  return true;
}

/// The sample's fate; has_previous: a previous delivered sample exists (and may be repeated).
/// Counts the kind that decided it (none for fresh).
template <class Counter>
SampleFate sample_fate(const ActiveFaults& faults, bool has_previous, Counter& counter) noexcept {
  if (take_fault(faults, FaultKind::drop, counter)) return SampleFate::dropped;
  if (has_previous && take_fault(faults, FaultKind::freeze_stamp, counter)) return SampleFate::repeat_previous;
  if (has_previous && take_fault(faults, FaultKind::freeze_data, counter)) return SampleFate::previous_values;
  return SampleFate::fresh;
}

/// stamp_jump and fault_bits on a delivered sample's stamp (s) and status word: the stamp moves
/// by the event's value (default +0.5 s); the status word gets the event's value OR-ed in
/// (default `default_bits`, the device's typical fault). Each counted when active.
template <class Counter>
void apply_stamp_and_status_faults(const ActiveFaults& faults, std::uint32_t default_bits, Counter& counter,
                                   double& stamp_s, std::uint32_t& status_bits) noexcept {
  if (take_fault(faults, FaultKind::stamp_jump, counter)) {
    const double jump = faults.value[static_cast<int>(FaultKind::stamp_jump)];
    stamp_s += std::isnan(jump) ? 0.5 : jump;
  }
  if (take_fault(faults, FaultKind::fault_bits, counter)) {
    const double bits = faults.value[static_cast<int>(FaultKind::fault_bits)];
    status_bits |= std::isnan(bits) ? default_bits : static_cast<std::uint32_t>(bits);
  }
}

}  // namespace pliant::hal::detail
