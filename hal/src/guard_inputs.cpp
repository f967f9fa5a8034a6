#include "pliant/hal/guard_inputs.hpp"

namespace pliant::hal {
namespace {

// The transport part shared by the three samples (every guard sample has the same flags).
template <typename Sample>
bool apply_status(HalStatus status, Sample& sample) noexcept {
  switch (status) {
    case HalStatus::ok:
      sample.valid = true;
      sample.timeout = false;
      sample.bus_off = false;
      return true;
    case HalStatus::no_data:
      sample.timeout = false;
      sample.bus_off = false;
      return false;
    case HalStatus::timeout: sample.timeout = true; return false;
    case HalStatus::bus_off: sample.bus_off = true; return false;
    default: sample.valid = false; return false;
  }
}

}  // namespace

void update_gripper_sample(HalStatus read_status, const GripperReading& reading, std::uint32_t monitor_flags,
                           GripperSample& sample) noexcept {
  if (!apply_status(read_status, sample)) return;
  sample.stamp_s = reading.header.stamp_s;
  sample.width_m = reading.width_m;
  sample.force_n = reading.force_n;
  sample.current_a = reading.current_a;
  sample.status_bits = reading.header.status_bits | monitor_flags;
}

void update_wrench_sample(HalStatus read_status, const WrenchReading& reading, std::uint32_t monitor_flags,
                          WrenchSample& sample) noexcept {
  if (!apply_status(read_status, sample)) return;
  sample.stamp_s = reading.header.stamp_s;
  for (int d = 0; d < 6; ++d) sample.wrench[d] = reading.wrench[d];
  sample.status_bits = reading.header.status_bits | monitor_flags;
}

void update_deformation_sample(HalStatus read_status, double stamp_s, double strain, std::uint32_t status_bits,
                               DeformationSample& sample) noexcept {
  if (!apply_status(read_status, sample)) return;
  sample.stamp_s = stamp_s;
  sample.strain = strain;
  sample.status_bits = status_bits;
}

}  // namespace pliant::hal
