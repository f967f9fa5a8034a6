// A recording played back through the HAL replay devices (pliant/hal/mock/replay_devices.hpp),
// with an online msm_beta estimate (core online_deformability) computed from what the particle
// observer delivers, exactly as a controller would compute it from a live tracker.
//
// Timing:
//   stepped   a ManualClock jumps to the next due sample of any device: the whole recording
//             as fast as it can be read, in recorded order, reproducible to the bit. While a
//             read fault (disconnect, timeout, bus_off) is active the clock moves in 1 ms steps,
//             so samples due meanwhile are lost as they would be live.
//   realtime  the steady clock, sleeping until the next due sample; speed scales recorded time.
// Faults: a fault script (pliant/hal/mock/fault_script.hpp; device names ft, gripper, observer)
// with times relative to the start of the replay; color and depth events are refused (a
// recording's media are not replayed here).
// The estimator steps on delivered stamps (dt = stamp difference x speed, so faults on stamps
// reach it as they would in a controller), drives the recording's driven particles while their
// windows are active (by the recorded time of the delivered frame) and scores the rest.
// Host code: allocates and throws (std::runtime_error; UsageError-like problems as
// std::invalid_argument).
#pragma once

#include <cstdint>
#include <functional>
#include <string>

#include "pliant/core/online_deformability.hpp"
#include "pliant/hal/camera.hpp"
#include "pliant/hal/device.hpp"
#include "pliant/hal/force_torque.hpp"
#include "pliant/hal/gripper.hpp"
#include "pliant/hal/mock/fault_schedule.hpp"
#include "pliant/hal/mock/replay_cursor.hpp"
#include "pliant/host/recording.hpp"

namespace pliant::host {

struct ReplayOptions {
  hal::ReplayTiming timing{hal::ReplayMode::stepped, 1.0};
  std::string fault_script;  ///< script text (empty: no faults)
  bool estimate = true;      ///< run the online msm_beta estimate on the particle frames
  double msm_alpha = 1.0;    ///< held msm_alpha when alpha_candidates is 1
  int candidates = 21;       ///< online estimator msm_beta grid size per alpha row (>= 3)
  int alpha_candidates = 3;  ///< msm_alpha rows on [0.3, 1]; 1: hold msm_alpha
  int step_candidates = 3;   ///< rows at 1, 2, 4 MSM steps per frame; the form is chosen online by BIC
  /// The quasi-static row (online_deformability.hpp): at most this many MSM iterations per
  /// candidate and frame, [0, kMaxEquilibriumIterations]; 0 leaves the row out.
  int equilibrium_iterations = 0;
};

enum class ReplayDevice : std::uint8_t { particles, wrench, gripper };
const char* replay_device_name(ReplayDevice device) noexcept;  ///< "particles", "wrench", "gripper"

/// One read that delivered a sample, or whose status changed to or from a failure.
struct ReplayEvent {
  ReplayDevice device = ReplayDevice::particles;
  hal::HalStatus status = hal::HalStatus::ok;     ///< ok: a sample; else the failure that started
  double now_s = 0;                               ///< replay clock at the read, from 0
  const hal::ParticleFrame* particles = nullptr;  ///< set for delivered particle frames
  const hal::WrenchReading* wrench = nullptr;
  const hal::GripperReading* gripper = nullptr;
  const OnlineDeformabilityEstimate* estimate = nullptr;  ///< after this frame, when estimating
  Status estimator_status = Status::ok;                   ///< of the update for this frame
};

struct ReplayDeviceSummary {
  bool present = false;
  hal::DeviceCounters counters;
  hal::FaultCounters injected;
};

struct ReplaySummary {
  ReplayDeviceSummary devices[3];  ///< by ReplayDevice
  bool estimated = false;
  OnlineDeformabilityEstimate estimate;
  std::uint32_t estimator_rejected_frames = 0;
  std::uint32_t estimator_empty_frames = 0;
  int skipped_rows = 0;      ///< wrench/gripper rows whose time did not increase
  double duration_s = 0;     ///< replay clock at the end
  bool interrupted = false;  ///< stopped by the `keep_going` callback
};

/// Plays `recording` back. `on_event` sees every event as it happens; `keep_going` is asked
/// before each cycle (return false to stop early, e.g. on a signal). Throws
/// std::invalid_argument for a bad fault script (its line and column in the message) or options,
/// std::runtime_error when a device or the estimator cannot be set up.
ReplaySummary replay_recording(const Recording& recording, const ReplayOptions& options,
                               const std::function<void(const ReplayEvent&)>& on_event,
                               const std::function<bool()>& keep_going = {});

}  // namespace pliant::host
