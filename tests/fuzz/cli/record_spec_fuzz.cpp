// libFuzzer target over the device specs of `pliant record` (host/cli/record_device_spec.cpp).
// Byte 0 picks the option (--color, --depth, --ft, --gripper), the rest is the spec text. Every
// input must parse or fail with DeviceSpecError whose message is one line naming the option; a
// parsed spec must satisfy the documented ranges.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <string_view>

#include "record_device_spec.hpp"

namespace {

void check(bool condition) {
  if (!condition) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace pliant::cli;
  if (size == 0) return 0;
  const auto role = static_cast<DeviceRole>(data[0] % 4);
  const std::string_view text(reinterpret_cast<const char*>(data + 1), size - 1);
  try {
    const DeviceSpec spec = parse_device_spec(role, text);
    check(spec.role == role);
    check(spec.text == text);
    const std::string kind = device_kind_name(spec.kind);
    check(text.substr(0, kind.size() + 1) == kind + ":");
    switch (spec.kind) {
      case DeviceKind::ati_can:
        check(spec.can_id <= 0x7f && !spec.location.empty() && spec.location.size() <= 15);
        break;
      case DeviceKind::robotous_can:
        check(spec.can_id <= 0x7ff && spec.can_response_1 <= 0x7ff && spec.can_response_2 <= 0x7ff);
        check(spec.can_id != spec.can_response_1 && spec.can_id != spec.can_response_2 &&
              spec.can_response_1 != spec.can_response_2);
        break;
      case DeviceKind::ft300_tcp:
      case DeviceKind::robotiq_tcp: check(spec.port >= 1 && spec.port <= 65535); [[fallthrough]];
      case DeviceKind::ft300_rtu:
      case DeviceKind::robotiq_rtu: check(spec.slave_id >= 0 && spec.slave_id <= 247 && !spec.location.empty()); break;
      case DeviceKind::libcamera: check(spec.any == spec.location.empty()); break;
      default: check(!spec.location.empty()); break;
    }
  } catch (const DeviceSpecError& e) {
    const std::string message = e.what();
    check(message.rfind(device_role_option(role), 0) == 0);
    check(message.find('\n') == std::string::npos && message.find('\r') == std::string::npos);
    check(message.size() < 1000);
  }
  return 0;
}
