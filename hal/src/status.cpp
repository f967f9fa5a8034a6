#include "pliant/hal/status.hpp"

namespace pliant::hal {

const char* hal_status_name(HalStatus status) noexcept {
  switch (status) {
    case HalStatus::ok: return "ok";
    case HalStatus::no_data: return "no_data";
    case HalStatus::wrong_state: return "wrong_state";
    case HalStatus::invalid_argument: return "invalid_argument";
    case HalStatus::unsupported: return "unsupported";
    case HalStatus::capacity_exceeded: return "capacity_exceeded";
    case HalStatus::disconnected: return "disconnected";
    case HalStatus::timeout: return "timeout";
    case HalStatus::bus_off: return "bus_off";
    case HalStatus::device_fault: return "device_fault";
    case HalStatus::io_error: return "io_error";
  }
  return "unknown";
}

}  // namespace pliant::hal
