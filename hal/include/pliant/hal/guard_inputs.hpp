// pliant hal -> core: the grasp guard's per-cycle samples from HAL reads.
//
// A supervisor keeps one sample per source across cycles and updates it after every read:
//   HalStatus s = gripper.read(reading);
//   update_gripper_sample(s, reading, monitor_flags, input.gripper);
// so that the guard sees exactly what the device did this cycle:
//   ok            -> a new sample: stamp, values and status bits (the device's, OR the stream
//                    monitor's flags), valid, no transport flag;
//   no_data       -> the previous sample unchanged (same stamp: the guard ages it and declares
//                    it stale after its timeout), transport flags cleared;
//   timeout       -> the previous sample with `timeout` set (the guard: not ok this cycle);
//   bus_off       -> the previous sample with `bus_off` set;
//   disconnected, io_error, device_fault, wrong_state and anything else
//                 -> the previous sample marked invalid (valid = false).
// The camera has no HAL sample of its own in the guard: the supervisor computes the strain of
// a frame (grasp_guard_measure_strain) and passes it to update_deformation_sample.
// Real-time safety: O(1), allocation-free, noexcept.
#pragma once

#include <cstdint>

#include "pliant/core/grasp_guard.hpp"
#include "pliant/hal/camera.hpp"
#include "pliant/hal/force_torque.hpp"
#include "pliant/hal/gripper.hpp"
#include "pliant/hal/stream_monitor.hpp"

namespace pliant::hal {

// The guard's default fault masks are these HAL conventions (the core repeats the bits, since it
// cannot include hal/): a change to either side must change both.
static_assert(kGuardStreamFaultBits == kStreamFaultMask, "core's stream flags differ from the monitor's");
static_assert(kGuardGripperFaultBits == kGripperFaultMask, "core's gripper fault bits differ from the HAL's");
static_assert(kGuardWrenchFaultBits == kFtFaultMask, "core's wrench fault bits differ from the HAL's");
static_assert(kGuardCameraFaultBits == kFrameFaultMask, "core's camera fault bits differ from the HAL's");

void update_gripper_sample(HalStatus read_status, const GripperReading& reading, std::uint32_t monitor_flags,
                           GripperSample& sample) noexcept;

void update_wrench_sample(HalStatus read_status, const WrenchReading& reading, std::uint32_t monitor_flags,
                          WrenchSample& sample) noexcept;

/// `strain`: the frame's measured strain (NaN when nothing was measured); `status_bits`: the
/// frame's own bits OR its monitor's flags. Used on ok; other statuses as above.
void update_deformation_sample(HalStatus read_status, double stamp_s, double strain, std::uint32_t status_bits,
                               DeformationSample& sample) noexcept;

}  // namespace pliant::hal
