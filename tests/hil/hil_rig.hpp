// The HIL rig: a stepped clock, a simulated grasp, the three mock devices on it, and the
// supervisor that sees only the devices. One rig per grasp.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "hil_supervisor.hpp"
#include "pliant/hal/mock/mock_force_torque.hpp"
#include "pliant/hal/mock/mock_gripper.hpp"
#include "pliant/hal/mock/mock_particle_observer.hpp"
#include "pliant/hal/mock/simulated_grasp.hpp"

namespace pliant::hil {

/// One object of the HIL suite: its simulation and its limits.
struct HilObject {
  std::string name;
  hal::SimulatedObjectConfig object;
  double max_strain = 0.1;
  double max_force_n = 60;
};

/// The suite: soft to stiff (msm_beta 0.95 .. 0.05), boxes, cylinders and balls of 30-64 mm,
/// strain limits 0.02-0.15 and force stiffness 600-30000 N/m.
std::vector<HilObject> hil_objects();

struct RigOptions {
  double rate_hz = 1000;  ///< control loop (and gripper, F/T sample) rate
  double camera_rate_hz = 30;
  double camera_noise_m = 3e-5;
  double pregrasp_gap_m = 0.008;  ///< the gripper starts this much wider than the object
  /// The guard's prediction table (init cost ~ beta points x (closure points + 8) relaxations).
  int prediction_beta_points = 11;
  int prediction_closure_points = 32;
  std::uint64_t seed = 1;
};

/// The design margin on the strain limit: the guard gets max_strain = (1 - margin) x the
/// object's limit. It covers the error of the contact width, which the guard takes from one
/// noisy gripper sample (5 um sd here) at the contact-force crossing: on the stiffest objects
/// that alone is worth up to ~2 % of strain.
inline constexpr double kStrainMargin = 0.05;

/// MSM iterations per frame of the estimator's quasi-static row: about what a squeeze at 20 mm/s
/// needs to settle each frame at the default tolerance (the 1-step rows lag this plant).
inline constexpr int kEquilibriumIterations = 64;

/// The supervisor configuration the HIL uses for an object (limits, timeouts, masks, the
/// estimator's quasi-static row).
SupervisorConfig hil_supervisor_config(const HilObject& object, const RigOptions& options);

struct Rig {
  hal::ManualClock clock{10.0};
  hal::SimulatedGrasp plant{clock};
  std::unique_ptr<hal::MockGripper> gripper;
  std::unique_ptr<hal::MockForceTorqueSensor> wrench;
  std::unique_ptr<hal::MockParticleObserver> observer;
  std::unique_ptr<Supervisor> supervisor;
  RigOptions options;
  hal::HalStatus status = hal::HalStatus::invalid_argument;
  std::int64_t cycles = 0;

  Rig(const HilObject& object, const RigOptions& rig_options);
  /// Advances the clock one period and runs one supervisor cycle.
  const CycleReport& step();
  double period_s() const { return 1.0 / options.rate_hz; }
};

}  // namespace pliant::hil
