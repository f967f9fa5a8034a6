// libFuzzer target over the HAL fault-script parser (hal/src/mock/fault_script.cpp).
//
// Any input must parse to ok or to a clean error (line >= 1, column >= 1, a message) without a
// crash or a sanitizer report. On ok, every event obeys the schedule's rules and the device's
// kinds, and the script printed back with full precision parses to the same events.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "pliant/hal/mock/fault_script.hpp"

namespace {

using pliant::hal::FaultDevice;
using pliant::hal::FaultEvent;
using pliant::hal::FaultKind;
using pliant::hal::FaultScript;
using pliant::hal::FaultScriptError;
using pliant::hal::HalStatus;

void check(bool condition) {
  if (!condition) std::abort();
}

std::string print(const FaultScript& script) {
  std::string text;
  char line[256];
  for (int d = 0; d < pliant::hal::kFaultDeviceCount; ++d) {
    const auto device = static_cast<FaultDevice>(d);
    const pliant::hal::FaultSchedule& s = script.of(device);
    for (int i = 0; i < s.size(); ++i) {
      const FaultEvent& e = s.event(i);
      int n = 0;
      if (std::isnan(e.value)) {
        n = std::snprintf(line, sizeof line, "%.17g %s %s %.17g\n", e.start_s, pliant::hal::fault_kind_name(e.kind),
                          pliant::hal::fault_device_name(device), e.duration_s);
      } else if (e.kind == FaultKind::fault_bits) {
        n = std::snprintf(line, sizeof line, "%.17g %s %s %.17g 0x%lx\n", e.start_s,
                          pliant::hal::fault_kind_name(e.kind), pliant::hal::fault_device_name(device), e.duration_s,
                          static_cast<unsigned long>(e.value));
      } else {
        n = std::snprintf(line, sizeof line, "%.17g %s %s %.17g %.17g\n", e.start_s,
                          pliant::hal::fault_kind_name(e.kind), pliant::hal::fault_device_name(device), e.duration_s,
                          e.value);
      }
      check(n > 0 && static_cast<std::size_t>(n) < sizeof line);
      text += line;
    }
  }
  return text;
}

bool same_event(const FaultEvent& a, const FaultEvent& b) {
  return a.kind == b.kind && a.start_s == b.start_s && a.duration_s == b.duration_s &&
         (a.value == b.value || (std::isnan(a.value) && std::isnan(b.value)));
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  FaultScript script;
  FaultScriptError error;
  const HalStatus status = pliant::hal::parse_fault_script(reinterpret_cast<const char*>(data), size, script, error);
  if (status != HalStatus::ok) {
    check(status == HalStatus::invalid_argument || status == HalStatus::capacity_exceeded);
    check(error.line >= 1 && error.column >= 1 && error.message != nullptr && error.message[0] != '\0');
    return 0;
  }
  check(error.line == 0);
  for (int d = 0; d < pliant::hal::kFaultDeviceCount; ++d) {
    const auto device = static_cast<FaultDevice>(d);
    const pliant::hal::FaultSchedule& s = script.of(device);
    check(s.size() <= pliant::hal::kFaultCapacity);
    for (int i = 0; i < s.size(); ++i) {
      const FaultEvent& e = s.event(i);
      check(std::isfinite(e.start_s) && std::isfinite(e.duration_s) && e.duration_s > 0);
      check((pliant::hal::fault_bit(e.kind) & pliant::hal::fault_device_kinds(device)) != 0);
      check(std::isnan(e.value) || std::isfinite(e.value));
    }
  }
  const std::string text = print(script);
  FaultScript again;
  check(pliant::hal::parse_fault_script(text.data(), text.size(), again, error) == HalStatus::ok);
  for (int d = 0; d < pliant::hal::kFaultDeviceCount; ++d) {
    const auto device = static_cast<FaultDevice>(d);
    check(script.of(device).size() == again.of(device).size());
    for (int i = 0; i < script.of(device).size(); ++i)
      check(same_event(script.of(device).event(i), again.of(device).event(i)));
  }
  return 0;
}
