#include "pliant/hal/mock/fault_script.hpp"

#include <charconv>
#include <cmath>
#include <cstring>

namespace pliant::hal {
namespace {

constexpr const char* kDeviceNames[kFaultDeviceCount] = {"gripper", "ft", "observer", "color", "depth"};
constexpr std::uint32_t kDeviceKinds[kFaultDeviceCount] = {kGripperFaults, kForceTorqueFaults, kObserverFaults,
                                                           kColorCameraFaults, kDepthCameraFaults};
constexpr int kMaxFields = 5;

struct Field {
  const char* begin = nullptr;
  std::size_t length = 0;
  std::size_t column = 0;  // 0-based offset in the line
};

bool parse_device(const Field& f, FaultDevice& device) noexcept {
  for (int d = 0; d < kFaultDeviceCount; ++d) {
    if (std::strlen(kDeviceNames[d]) == f.length && std::memcmp(kDeviceNames[d], f.begin, f.length) == 0) {
      device = static_cast<FaultDevice>(d);
      return true;
    }
  }
  return false;
}

// A finite decimal number filling the whole field (from_chars: no locale, no whitespace, no
// leading '+'; "nan" and "inf" parse but are refused as not finite).
bool parse_number(const Field& f, double& value) noexcept {
  const char* end = f.begin + f.length;
  const auto result = std::from_chars(f.begin, end, value, std::chars_format::general);
  return result.ec == std::errc() && result.ptr == end && std::isfinite(value);
}

// An integer in [0, 2^32): decimal or 0x-hex.
bool parse_bits(const Field& f, double& value) noexcept {
  const char* begin = f.begin;
  const char* end = f.begin + f.length;
  int base = 10;
  if (f.length > 2 && begin[0] == '0' && (begin[1] == 'x' || begin[1] == 'X')) {
    begin += 2;
    base = 16;
  }
  std::uint64_t bits = 0;
  const auto result = std::from_chars(begin, end, bits, base);
  if (result.ec != std::errc() || result.ptr != end || begin == end || bits > 0xffffffffull) return false;
  value = static_cast<double>(bits);
  return true;
}

HalStatus fail(FaultScriptError& error, int line, std::size_t column, const char* message, HalStatus status) noexcept {
  error.line = line;
  error.column = static_cast<int>(column) + 1;
  error.message = message;
  return status;
}

}  // namespace

const char* fault_device_name(FaultDevice device) noexcept {
  const int d = static_cast<int>(device);
  return d >= 0 && d < kFaultDeviceCount ? kDeviceNames[d] : "unknown";
}

std::uint32_t fault_device_kinds(FaultDevice device) noexcept {
  const int d = static_cast<int>(device);
  return d >= 0 && d < kFaultDeviceCount ? kDeviceKinds[d] : 0u;
}

int FaultScript::events() const noexcept {
  int total = 0;
  for (const FaultSchedule& s : schedules) total += s.size();
  return total;
}

HalStatus parse_fault_script(const char* text, std::size_t length, FaultScript& script,
                             FaultScriptError& error) noexcept {
  for (FaultSchedule& s : script.schedules) s.clear();
  error = FaultScriptError{};
  if (text == nullptr && length > 0) return fail(error, 1, 0, "no text", HalStatus::invalid_argument);
  std::size_t pos = 0;
  int line = 0;
  while (pos < length) {
    ++line;
    const char* start = text + pos;
    std::size_t line_length = 0;
    while (pos + line_length < length && start[line_length] != '\n') ++line_length;
    pos += line_length + 1;
    if (line_length > 0 && start[line_length - 1] == '\r') --line_length;
    // Split into fields up to a comment.
    Field fields[kMaxFields];
    int count = 0;
    std::size_t i = 0;
    while (i < line_length && start[i] != '#') {
      if (start[i] == ' ' || start[i] == '\t') {
        ++i;
        continue;
      }
      const std::size_t begin = i;
      while (i < line_length && start[i] != ' ' && start[i] != '\t' && start[i] != '#') ++i;
      if (count == kMaxFields)
        return fail(error, line, begin, "too many fields (t_s kind device duration_s [value])",
                    HalStatus::invalid_argument);
      fields[count].begin = start + begin;
      fields[count].length = i - begin;
      fields[count].column = begin;
      ++count;
    }
    if (count == 0) continue;
    if (count < 4)
      return fail(error, line, count > 0 ? fields[count - 1].column : 0,
                  "too few fields (t_s kind device duration_s [value])", HalStatus::invalid_argument);
    FaultEvent event;
    if (!parse_number(fields[0], event.start_s))
      return fail(error, line, fields[0].column, "start time is not a finite number", HalStatus::invalid_argument);
    if (!parse_fault_kind(fields[1].begin, fields[1].length, event.kind)) {
      return fail(error, line, fields[1].column, "unknown fault kind", HalStatus::invalid_argument);
    }
    FaultDevice device = FaultDevice::gripper;
    if (!parse_device(fields[2], device))
      return fail(error, line, fields[2].column, "unknown device (gripper, ft, observer, color, depth)",
                  HalStatus::invalid_argument);
    if ((fault_bit(event.kind) & fault_device_kinds(device)) == 0) {
      return fail(error, line, fields[1].column, "fault kind not supported by this device",
                  HalStatus::invalid_argument);
    }
    if (!parse_number(fields[3], event.duration_s) || !(event.duration_s > 0)) {
      return fail(error, line, fields[3].column, "duration is not a finite number > 0", HalStatus::invalid_argument);
    }
    if (count == 5) {
      const bool parsed = event.kind == FaultKind::fault_bits ? parse_bits(fields[4], event.value)
                                                              : parse_number(fields[4], event.value);
      if (!parsed)
        return fail(error, line, fields[4].column, "value is not a valid number for this kind",
                    HalStatus::invalid_argument);
    }
    const HalStatus added = script.schedules[static_cast<int>(device)].add(event);
    if (added == HalStatus::capacity_exceeded) return fail(error, line, 0, "too many events for one device", added);
    if (added != HalStatus::ok)
      return fail(error, line, count == 5 ? fields[4].column : 0, "value out of range for this kind", added);
  }
  return HalStatus::ok;
}

}  // namespace pliant::hal
