// pliant hal mocks: scripted fault injection.
//
// A FaultSchedule is a fixed-capacity list of events {start_s, duration_s, kind, value}; an
// event is active on the half-open interval [start_s, start_s + duration_s) of the device's
// clock. Every mock device holds one schedule and applies it while it runs; what it injected
// is counted per kind in FaultCounters.
//
// Two groups of kinds:
//   sample faults, decided at a sample's capture time (one count per affected sample):
//     drop          the sample is never delivered (its sequence number is skipped)
//     freeze_data   delivered with a new stamp and sequence, but the values of the previous
//                   delivered sample, bit for bit (a sensor that stopped updating)
//     freeze_stamp  the previous delivered sample again, its stamp included, under a new
//                   sequence number (a driver re-sending a stale sample)
//     nan           every value of the sample is NaN (a depth frame: every pixel 0)
//     stamp_jump    the stamp is off by `value` seconds (default +0.5; negative goes back)
//     fault_bits    the device's status word gets `value` (an integer; default: the device's
//                   typical fault, e.g. a Robotiq over-current code or the ATI supply-low bit)
//     occlude       (particle observer) the fraction `value` (default 0.5) of the particles,
//                   those with the largest rest y, is unobserved (NaN)
//   read faults, decided at the time of the call (one count per affected read or write):
//     disconnect    read and write return disconnected; samples due meanwhile are lost
//     bus_off       (force/torque) read returns bus_off
//     timeout       read and write return timeout (a Modbus poll without answer)
// A device refuses kinds it cannot have (unsupported): bus_off only for the force/torque
// sensor, occlude only for the particle observer.
// Where events overlap, each kind uses the first added event of that kind; read faults take
// precedence over sample faults (disconnect, then bus_off, then timeout).
//
// Real-time safety: the schedule is a fixed array (kFaultCapacity events); add, clear and the
// per-sample lookup (O(events)) never allocate and never throw.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>

#include "pliant/hal/status.hpp"

namespace pliant::hal {

enum class FaultKind : std::uint8_t {
  drop = 0,
  freeze_data,
  freeze_stamp,
  nan,
  stamp_jump,
  fault_bits,
  occlude,
  disconnect,
  bus_off,
  timeout,
  count
};
inline constexpr int kFaultKindCount = static_cast<int>(FaultKind::count);

constexpr std::uint32_t fault_bit(FaultKind kind) noexcept { return 1u << static_cast<unsigned>(kind); }
/// Kinds every mock supports.
inline constexpr std::uint32_t kCommonFaults = fault_bit(FaultKind::drop) | fault_bit(FaultKind::freeze_data) |
                                               fault_bit(FaultKind::freeze_stamp) | fault_bit(FaultKind::nan) |
                                               fault_bit(FaultKind::stamp_jump) | fault_bit(FaultKind::fault_bits) |
                                               fault_bit(FaultKind::disconnect) | fault_bit(FaultKind::timeout);

/// The kinds each mock accepts.
inline constexpr std::uint32_t kGripperFaults = kCommonFaults;
inline constexpr std::uint32_t kForceTorqueFaults = kCommonFaults | fault_bit(FaultKind::bus_off);
inline constexpr std::uint32_t kObserverFaults = kCommonFaults | fault_bit(FaultKind::occlude);
inline constexpr std::uint32_t kColorCameraFaults = kCommonFaults & ~fault_bit(FaultKind::nan);
inline constexpr std::uint32_t kDepthCameraFaults = kCommonFaults;

/// Stable lower-case names ("drop", "freeze_data", ...), as in fault scripts.
const char* fault_kind_name(FaultKind kind) noexcept;
/// Parses a name of fault_kind_name (exact, case-sensitive); false when unknown.
bool parse_fault_kind(const char* text, std::size_t length, FaultKind& kind) noexcept;

struct FaultEvent {
  double start_s = 0;     ///< on the device's clock
  double duration_s = 0;  ///< > 0; active on [start_s, start_s + duration_s)
  FaultKind kind = FaultKind::drop;
  /// Kind parameter (stamp_jump seconds, fault_bits word, occlude fraction); NaN: the default.
  double value = std::numeric_limits<double>::quiet_NaN();
};

inline constexpr int kFaultCapacity = 32;

/// The faults active at one instant: a kind bit set and each active kind's value.
struct ActiveFaults {
  std::uint32_t kinds = 0;
  double value[kFaultKindCount] = {};
  bool has(FaultKind kind) const noexcept { return (kinds & fault_bit(kind)) != 0; }
};

class FaultSchedule {
 public:
  /// Adds one event. invalid_argument: start not finite, duration not finite and > 0, kind out
  /// of range, or a value that is not NaN and not finite (stamp_jump), not an integer in
  /// [0, 2^32) (fault_bits), or not in (0, 1] (occlude). capacity_exceeded when full.
  HalStatus add(const FaultEvent& event) noexcept;
  void clear() noexcept { size_ = 0; }
  int size() const noexcept { return size_; }
  const FaultEvent& event(int index) const noexcept { return events_[index]; }
  /// The kinds used by any event.
  std::uint32_t kinds() const noexcept;
  /// The active faults at t_s. O(size).
  ActiveFaults active_at(double t_s) const noexcept;

 private:
  FaultEvent events_[kFaultCapacity] = {};
  int size_ = 0;
};

/// What a mock injected, per kind: affected samples (sample faults) or calls (read faults).
struct FaultCounters {
  std::uint64_t injected[kFaultKindCount] = {};
  std::uint64_t of(FaultKind kind) const noexcept { return injected[static_cast<int>(kind)]; }
  std::uint64_t total() const noexcept {
    std::uint64_t sum = 0;
    for (std::uint64_t n : injected) sum += n;
    return sum;
  }
};

/// The read fault `schedule` has active at now_s (disconnect, then bus_off, then timeout),
/// counted in `counters`; ok when none. Shared by every mock's read path.
HalStatus apply_read_fault(const FaultSchedule& schedule, double now_s, FaultCounters& counters) noexcept;

}  // namespace pliant::hal
