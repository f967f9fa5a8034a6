#include "pliant/hal/device.hpp"

#include <exception>
#include <new>
#include <stdexcept>

namespace pliant::hal {

const char* lifecycle_state_name(LifecycleState state) noexcept {
  switch (state) {
    case LifecycleState::unconfigured: return "unconfigured";
    case LifecycleState::inactive: return "inactive";
    case LifecycleState::active: return "active";
  }
  return "unknown";
}

HalStatus Device::configure() noexcept {
  if (state_ != LifecycleState::unconfigured) {
    ++counters_.lifecycle_errors;
    return HalStatus::wrong_state;
  }
  counters_ = DeviceCounters{};
  last_sequence_ = 0;
  unreachable_ = false;
  HalStatus status = HalStatus::ok;
  // The edge where exceptions stop (allocation, or a device library that throws).
  try {
    status = on_configure();
  } catch (const std::bad_alloc&) {
    status = HalStatus::capacity_exceeded;
  } catch (const std::length_error&) {
    status = HalStatus::capacity_exceeded;
  } catch (const std::exception&) {
    status = HalStatus::io_error;
  }
  if (status == HalStatus::ok) state_ = LifecycleState::inactive;
  return status;
}

HalStatus Device::start() noexcept {
  if (state_ != LifecycleState::inactive) {
    ++counters_.lifecycle_errors;
    return HalStatus::wrong_state;
  }
  const HalStatus status = on_start();
  if (status == HalStatus::ok) state_ = LifecycleState::active;
  return status;
}

HalStatus Device::stop() noexcept {
  if (state_ != LifecycleState::active) {
    ++counters_.lifecycle_errors;
    return HalStatus::wrong_state;
  }
  // Stopping cannot be refused: whatever the hook reports, the device no longer streams.
  const HalStatus status = on_stop();
  state_ = LifecycleState::inactive;
  return status;
}

HalStatus Device::cleanup() noexcept {
  if (state_ != LifecycleState::inactive) {
    ++counters_.lifecycle_errors;
    return HalStatus::wrong_state;
  }
  const HalStatus status = on_cleanup();
  state_ = LifecycleState::unconfigured;
  return status;
}

bool Device::admit() noexcept {
  if (state_ == LifecycleState::active) return true;
  ++counters_.lifecycle_errors;
  return false;
}

void Device::account_fault(HalStatus status) noexcept {
  switch (status) {
    case HalStatus::timeout: ++counters_.timeouts; break;
    case HalStatus::bus_off: ++counters_.bus_off; break;
    case HalStatus::disconnected:
      ++counters_.disconnected;
      if (!unreachable_) ++counters_.disconnects;
      unreachable_ = true;
      return;
    case HalStatus::device_fault: ++counters_.device_faults; break;
    case HalStatus::io_error: ++counters_.io_errors; break;
    default: break;
  }
}

void Device::account_read(HalStatus status, const SampleHeader& header) noexcept {
  ++counters_.reads;
  if (is_fault(status)) {
    account_fault(status);
    return;
  }
  // Only a delivered sample proves the device is back: a driver may answer no_data without any
  // I/O (poll rate limits, reconnect back-off), which would count a reconnect per read.
  if (unreachable_ && status == HalStatus::ok) {
    unreachable_ = false;
    ++counters_.reconnects;
  }
  if (status == HalStatus::no_data) {
    ++counters_.no_data;
    return;
  }
  if (status != HalStatus::ok) return;
  ++counters_.samples;
  if ((header.status_bits & fault_mask_) != 0) ++counters_.fault_samples;
  if (header.sequence > last_sequence_ + 1) counters_.dropped += header.sequence - last_sequence_ - 1;
  if (header.sequence > last_sequence_) last_sequence_ = header.sequence;
}

void Device::account_write(HalStatus status) noexcept {
  ++counters_.writes;
  if (is_fault(status)) {
    account_fault(status);
    ++counters_.rejected_writes;
    return;
  }
  if (status != HalStatus::ok) {
    ++counters_.rejected_writes;
    return;
  }
  if (unreachable_) {
    unreachable_ = false;
    ++counters_.reconnects;
  }
}

}  // namespace pliant::hal
