#include "pliant/hal/mock/fault_schedule.hpp"

#include <cmath>
#include <cstring>
#include <initializer_list>

namespace pliant::hal {
namespace {

constexpr const char* kNames[kFaultKindCount] = {"drop",       "freeze_data", "freeze_stamp", "nan",     "stamp_jump",
                                                 "fault_bits", "occlude",     "disconnect",   "bus_off", "timeout"};

bool valid_value(FaultKind kind, double value) noexcept {
  if (std::isnan(value)) return true;
  switch (kind) {
    case FaultKind::stamp_jump: return std::isfinite(value);
    case FaultKind::fault_bits: return value >= 0 && value < 4294967296.0 && std::floor(value) == value;
    case FaultKind::occlude: return value > 0 && value <= 1;
    default: return std::isfinite(value);
  }
}

}  // namespace

const char* fault_kind_name(FaultKind kind) noexcept {
  const int index = static_cast<int>(kind);
  return index >= 0 && index < kFaultKindCount ? kNames[index] : "unknown";
}

bool parse_fault_kind(const char* text, std::size_t length, FaultKind& kind) noexcept {
  if (text == nullptr) return false;
  for (int k = 0; k < kFaultKindCount; ++k) {
    if (std::strlen(kNames[k]) == length && std::memcmp(kNames[k], text, length) == 0) {
      kind = static_cast<FaultKind>(k);
      return true;
    }
  }
  return false;
}

HalStatus FaultSchedule::add(const FaultEvent& event) noexcept {
  const int kind = static_cast<int>(event.kind);
  if (!std::isfinite(event.start_s) || !std::isfinite(event.duration_s) || !(event.duration_s > 0) || kind < 0 ||
      kind >= kFaultKindCount || !valid_value(event.kind, event.value)) {
    return HalStatus::invalid_argument;
  }
  if (size_ >= kFaultCapacity) return HalStatus::capacity_exceeded;
  events_[size_++] = event;
  return HalStatus::ok;
}

std::uint32_t FaultSchedule::kinds() const noexcept {
  std::uint32_t kinds = 0;
  for (int i = 0; i < size_; ++i) kinds |= fault_bit(events_[i].kind);
  return kinds;
}

ActiveFaults FaultSchedule::active_at(double t_s) const noexcept {
  ActiveFaults active;
  for (int i = 0; i < size_; ++i) {
    const FaultEvent& e = events_[i];
    if (!(t_s >= e.start_s && t_s < e.start_s + e.duration_s)) continue;
    if (active.has(e.kind)) continue;
    active.kinds |= fault_bit(e.kind);
    active.value[static_cast<int>(e.kind)] = e.value;
  }
  return active;
}

HalStatus apply_read_fault(const FaultSchedule& schedule, double now_s, FaultCounters& counters) noexcept {
  const ActiveFaults active = schedule.active_at(now_s);
  for (const FaultKind kind : {FaultKind::disconnect, FaultKind::bus_off, FaultKind::timeout}) {
    if (!active.has(kind)) continue;
    ++counters.injected[static_cast<int>(kind)];
    return kind == FaultKind::disconnect ? HalStatus::disconnected
           : kind == FaultKind::bus_off  ? HalStatus::bus_off
                                         : HalStatus::timeout;
  }
  return HalStatus::ok;
}

}  // namespace pliant::hal
