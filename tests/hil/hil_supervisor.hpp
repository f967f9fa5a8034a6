// The HIL supervisor: a grasp controller that sees the world only through HAL devices.
//
// Every control cycle it reads the gripper, the F/T sensor and the particle observer (a new
// frame arrives at camera rate), runs each stream through a hal::StreamMonitor, turns the reads
// into grasp-guard samples (hal/guard_inputs.hpp), measures the strain of each new frame
// (grasp_guard_measure_strain), updates the online msm_beta estimate with it (driven by the
// particles at the jaws once the guard reports contact), runs
// grasp_guard_update and commands the gripper:
//   ok    - close toward a target far deeper than any safe closure, but never past
//           safe_width_m, at close_speed; the force command is the guard's allowed force;
//   limit - hold (stop command) once, on entering;
//   stop  - the verdict's stop_action: open (move out to the contact width + open_margin) or
//           freeze (stop command).
// Phases: learning (gripper parked open; the first rest_frames frames are averaged into the
// object's rest shape, from which the MSM model, the guard and the estimator are built),
// approach (fast to the object's visible width + approach_gap_m), squeeze (the loop above).
//
// The squeeze axis is the world x axis and the gripper is centred on x = 0 (the hand-eye
// calibration a real rig would supply). Memory: the model, guard and estimator are allocated
// once, when learning ends; afterwards a cycle allocates nothing.
#pragma once

#include <chrono>
#include <cstdint>
#include <vector>

#include "pliant/core/grasp_guard.hpp"
#include "pliant/core/online_deformability.hpp"
#include "pliant/hal/camera.hpp"
#include "pliant/hal/clock.hpp"
#include "pliant/hal/force_torque.hpp"
#include "pliant/hal/gripper.hpp"
#include "pliant/hal/stream_monitor.hpp"

namespace pliant::hil {

struct SupervisorConfig {
  double close_speed_m_per_s = 0.004;
  double approach_speed_m_per_s = 0.05;
  double approach_gap_m = 0.0015;  ///< approach ends this far outside the visible width
  /// ... once the width read is within this of that target (a gripper whose width comes in
  /// position counts, e.g. a Robotiq's 0.33 mm, needs about one count).
  double approach_tolerance_m = 1e-4;
  double open_speed_m_per_s = 0.02;
  double open_margin_m = 0.002;
  double target_closure_fraction = 0.45;  ///< squeeze target: this fraction of the width, far past safe
  int rest_frames = 4;
  /// Floor on the estimate's sd passed to the guard: the online estimator's own sd (from the
  /// curvature of its residual curve) ignores its model error and is overconfident here.
  double beta_std_floor = 0.05;
  double contact_band = 0.2;  ///< x model spacing: observed particles this close to a jaw plane are driven
  OnlineDeformabilityConfig estimator;
  GraspGuardConfig guard;  ///< limits, timeouts and masks (see hil_scenarios for the HIL's)
  hal::StreamMonitorConfig gripper_monitor;
  hal::StreamMonitorConfig wrench_monitor;
  hal::StreamMonitorConfig camera_monitor;
};

enum class Phase : std::uint8_t { learning, approach, squeeze, failed };

struct CycleReport {
  std::int64_t cycle = 0;
  double now_s = 0;
  Phase phase = Phase::learning;
  bool guarded = false;  ///< the guard ran this cycle (after learning)
  GraspGuardOutput out;
  hal::HalStatus gripper_read = hal::HalStatus::no_data;
  hal::HalStatus wrench_read = hal::HalStatus::no_data;
  hal::HalStatus frame_read = hal::HalStatus::no_data;
  hal::HalStatus command = hal::HalStatus::no_data;  ///< last write's status this cycle (no_data: none)
  bool new_frame = false;
  double command_width_m = 0;
  /// Monotonic wall-clock instants (for latency benchmarks): the cycle began (its gripper read
  /// went out), the gripper read returned, the guard's verdict was out, the cycle ended (after
  /// its command went out).
  std::chrono::steady_clock::time_point cycle_start_at{}, gripper_sample_at{}, verdict_at{}, cycle_end_at{};
};

class Supervisor {
 public:
  using Vec = Eigen::Vector3d;

  Supervisor(hal::Gripper& gripper, hal::ForceTorqueSensor& wrench, hal::ParticleObserver& observer,
             const hal::Clock& clock, const SupervisorConfig& config);
  Supervisor(const Supervisor&) = delete;
  Supervisor& operator=(const Supervisor&) = delete;

  /// Starts the (configured) devices; returns the first failing status.
  hal::HalStatus start();
  /// One control cycle at the clock's now.
  const CycleReport& cycle();

  Phase phase() const { return phase_; }
  const CycleReport& last() const { return report_; }
  const GraspGuard<3, double>& guard() const { return guard_; }
  OnlineDeformabilityEstimate estimate() const;
  double visible_width_m() const { return visible_width_m_; }
  const hal::StreamMonitor& camera_monitor() const { return camera_monitor_; }
  std::uint64_t frames() const { return frames_; }

 private:
  void learn(const hal::ParticleFrame& frame);
  bool build();
  void on_frame(const hal::ParticleFrame& frame, std::uint32_t flags);
  void command(const GraspGuardOutput& out);
  void write_move(double width_m, double speed_m_per_s, double force_n);
  void write_stop();

  hal::Gripper& gripper_;
  hal::ForceTorqueSensor& wrench_;
  hal::ParticleObserver& observer_;
  const hal::Clock& clock_;
  SupervisorConfig config_;
  Phase phase_ = Phase::learning;
  CycleReport report_;
  std::int64_t cycles_ = 0;
  std::uint64_t frames_ = 0;

  hal::StreamMonitor gripper_monitor_, wrench_monitor_, camera_monitor_;
  hal::GripperReading gripper_reading_;
  hal::WrenchReading wrench_reading_;
  GraspGuardInput input_;
  bool have_width_ = false;
  double width_m_ = 0;
  bool in_contact_ = false;  ///< the guard's contact state of the last cycle

  // learning
  std::vector<double> rest_sum_;
  std::vector<int> rest_count_;
  int rest_frames_seen_ = 0;

  // object model, guard, estimator (built once)
  std::vector<double> rest_;
  std::vector<int> all_;
  std::vector<unsigned char> model_block_, guard_block_, estimator_block_;
  MsmModel<3, double> model_;
  GraspGuard<3, double> guard_;
  OnlineDeformability<3, double> estimator_;
  std::vector<Vec> observed_;
  std::vector<int> driven_ids_;
  std::vector<Vec> driven_targets_;
  double visible_width_m_ = 0;
  double last_frame_stamp_s_ = 0;
  bool has_frame_stamp_ = false;

  // commands
  bool has_command_ = false;
  hal::GripperCommandKind last_kind_ = hal::GripperCommandKind::stop;
  double last_width_m_ = 0;
  double last_force_n_ = 0;
  GraspVerdict last_verdict_ = GraspVerdict::ok;
};

}  // namespace pliant::hil
