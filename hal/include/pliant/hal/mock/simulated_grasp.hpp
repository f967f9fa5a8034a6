// pliant hal mocks: the plant behind the mock devices - a soft object (a core MSM model in 3D)
// squeezed between the two rigid jaws of a parallel gripper.
//
// The object: particles on a cubic lattice of spacing `spacing_m` filling a box, a cylinder
//   (its axis along z) or a ball, centred on the origin; every particle drivable, none fixed,
//   default clusters (one per particle, radius 1.5 x spacing), msm_beta as configured. World
//   frame = the camera frame of the observer mock, metres.
// The jaws: two planes normal to x, at x = -width/2 (jaw A) and x = +width/2 (jaw B). The
//   object's width along x is its extent E (extreme particle centres), so the jaws touch it at
//   width E; closure c = E - width. The width moves toward the commanded target at the
//   commanded speed (rate limited, at most jaw_max_speed_m_per_s); a move stops early when
//   the grip force reaches the commanded force (object detected, as a Robotiq does). While
//   the actuator is faulted the jaws hold. The width is clamped to
//   [E x (1 - max_closure_fraction), max_width_m]: a hard stop that keeps the simulation
//   inside the range where a quasi-static MSM squeeze means something.
// The contact (the guard's prediction uses the same rule): at first contact the particles
//   within 0.25 spacing of the extreme x layer stick to their jaw; a free particle that crosses
//   a jaw plane is projected onto it and sticks from then on. A stuck particle moves with its
//   jaw (driven target: its position when it joined, shifted along x by the jaw's travel since)
//   and is released when the jaw retreats past the point where it joined.
// Dynamics: quasi-static. Every period_s of the clock the jaw moves, then the object relaxes
//   with up to max_steps_per_period core msm_steps (unit pseudo-time step, msm_alpha 1,
//   momentum 0.5 + 0.4 msm_beta, velocities zeroed at the start of each period), ending early
//   once no particle moves more than settle_tolerance x spacing in two successive steps.
// Grip force (the law the mock gripper and F/T sensor report, N):
//     F = stiffness_n_per_m x c x (1 + stiffening x c / E)   for c > 0, else 0.
//   MSM has no force scale, so this law is separate from the shape: choose it per object.
// Ground truth: true_max_strain() is the largest principal (Biot) strain |stretch - 1| of any
//   cluster of the current state (the grasp guard's strain measure, computed here on its own:
//   per cluster the affine fit A = A_pq A_qq^+, stretches from the eigenvalues of A^T A within
//   the cluster's span); peak_true_strain() is its maximum since configure or reset.
//
// Time: sync() advances the simulation to the clock's now in whole periods (the mock devices
//   call it on every read and write, so one plant serves any number of devices). At most
//   max_catch_up_periods periods per call; a longer gap is skipped (counted), so a call is
//   bounded: O(max_catch_up_periods x max_steps_per_period x cluster memberships).
// Memory: configure() allocates everything (std::vector); sync() and the jaw commands never
//   allocate and never throw. Not thread-safe: drive the plant and its devices from one thread.
#pragma once

#include <cstdint>
#include <limits>
#include <vector>

#include <Eigen/Core>

#include "pliant/core/msm.hpp"
#include "pliant/hal/clock.hpp"
#include "pliant/hal/status.hpp"

namespace pliant::hal {

enum class ObjectShape : std::uint8_t { box, cylinder, ball };

struct SimulatedObjectConfig {
  ObjectShape shape = ObjectShape::box;
  /// box: particles along x, y, z (each >= 2). cylinder: radius nx cells (2 nx + 1 particles
  /// across, in x and y), nz particles along its axis z; ny unused. ball: radius nx cells.
  int nx = 6, ny = 5, nz = 4;
  double spacing_m = 0.008;         ///< lattice spacing, > 0
  double msm_beta = 0.5;            ///< [0, 1]
  double stiffness_n_per_m = 2000;  ///< > 0
  double stiffening = 0;            ///< >= 0
};

struct SimulatedGraspConfig {
  SimulatedObjectConfig object;
  double period_s = 0.001;                                            ///< > 0
  int max_steps_per_period = 24;                                      ///< >= 1
  double settle_tolerance = 1e-6;                                     ///< x spacing, > 0
  double jaw_max_speed_m_per_s = 0.15;                                ///< > 0
  double max_width_m = 0.085;                                         ///< > extent
  double initial_width_m = std::numeric_limits<double>::quiet_NaN();  ///< NaN: max_width_m
  double max_closure_fraction = 0.5;                                  ///< (0, 1)
  int max_catch_up_periods = 2000;                                    ///< >= 1
};

struct SimulatedGraspCounters {
  std::uint64_t periods = 0;  ///< periods simulated
  std::uint64_t msm_steps = 0;
  std::uint64_t unsettled_periods = 0;  ///< periods that used every step without settling
  std::uint64_t skipped_periods = 0;    ///< periods skipped by a sync() beyond max_catch_up_periods
  std::uint64_t step_errors = 0;        ///< msm_step calls that did not return ok
  std::uint64_t force_stops = 0;        ///< moves stopped by the force limit
};

class SimulatedGrasp {
 public:
  using Vec = Eigen::Vector3d;

  explicit SimulatedGrasp(const Clock& clock) noexcept : clock_(clock) {}
  SimulatedGrasp(const SimulatedGrasp&) = delete;
  SimulatedGrasp& operator=(const SimulatedGrasp&) = delete;

  /// Builds the object and resets the jaws to initial_width_m at the clock's now. May
  /// allocate. invalid_argument for a field out of range or an object with fewer than 8
  /// particles; the MSM model's own errors map to invalid_argument as well.
  HalStatus configure(const SimulatedGraspConfig& config);
  bool configured() const noexcept { return configured_; }

  /// Object at rest, jaws at initial_width_m, no command, counters kept, peak strain cleared.
  void reset() noexcept;
  /// Advances to the clock's now (see the top of the file).
  void sync() noexcept;

  // --- the actuator (the mock gripper's commands) ----------------------------------------------
  void command_move(double width_m, double speed_m_per_s, double force_limit_n) noexcept;
  void command_stop() noexcept;
  void command_open(double speed_m_per_s) noexcept;
  /// A faulted actuator holds its width and ignores motion until cleared.
  void set_actuator_fault(bool faulted) noexcept { actuator_fault_ = faulted; }

  // --- state (as of the last sync) --------------------------------------------------------------
  double time_s() const noexcept { return time_s_; }
  double width_m() const noexcept { return width_m_; }
  double target_width_m() const noexcept { return target_width_m_; }
  bool moving() const noexcept { return moving_; }
  bool object_detected() const noexcept { return object_detected_; }
  double closure_m() const noexcept { return extent_m_ - width_m_; }
  double grip_force_n() const noexcept { return force_n_; }
  double extent_m() const noexcept { return extent_m_; }
  double max_width_m() const noexcept { return config_.max_width_m; }
  double min_width_m() const noexcept { return extent_m_ * (1 - config_.max_closure_fraction); }
  double true_max_strain() const noexcept { return strain_; }
  double peak_true_strain() const noexcept { return peak_strain_; }
  int particle_count() const noexcept { return model_.particle_count; }
  const Vec* positions() const noexcept { return state_.position; }
  const Vec* rest_positions() const noexcept { return model_.rest; }
  int contact_count() const noexcept;
  const SimulatedGraspConfig& config() const noexcept { return config_; }
  const SimulatedGraspCounters& counters() const noexcept { return counters_; }
  const MsmModel<3, double>& model() const noexcept { return model_; }

  /// The grip force law at closure c (m), N.
  double force_at(double closure_m) const noexcept;
  /// Largest cluster strain of `positions` ([particle_count]) against the rest shape.
  double max_strain(const Vec* positions) const noexcept;

 private:
  void step_period() noexcept;
  void move_jaws() noexcept;
  void relax() noexcept;
  void update_contacts() noexcept;

  const Clock& clock_;
  SimulatedGraspConfig config_;
  bool configured_ = false;
  std::vector<double> rest_;
  std::vector<int> all_ids_;
  std::vector<unsigned char> model_block_;
  std::vector<unsigned char> state_block_;
  MsmModel<3, double> model_;
  MsmState<3, double> state_;
  MsmParams<3, double> params_;
  std::vector<Eigen::Matrix3d> span_;  ///< per cluster: projector onto its span
  std::vector<std::int8_t> side_;      ///< -1 jaw A, +1 jaw B, 0 free
  std::vector<Vec> anchor_;
  std::vector<double> anchor_closure_;
  std::vector<std::uint8_t> initial_contact_;
  std::vector<int> driven_ids_;
  std::vector<Vec> driven_targets_;
  std::vector<Vec> previous_;
  double low_ = 0, high_ = 0, extent_m_ = 0;
  double tolerance_m_ = 0;
  // jaw and time
  double time_s_ = 0;
  double width_m_ = 0;
  double target_width_m_ = 0;
  double speed_m_per_s_ = 0;
  double force_limit_n_ = std::numeric_limits<double>::infinity();
  bool moving_ = false;
  bool object_detected_ = false;
  bool actuator_fault_ = false;
  bool in_contact_ = false;
  bool settled_ = true;
  double force_n_ = 0;
  double strain_ = 0;
  double peak_strain_ = 0;
  SimulatedGraspCounters counters_;
};

}  // namespace pliant::hal
