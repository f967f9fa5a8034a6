// Free-running MSM simulation of a whole recording with every physics knob `diagnose` uses.
//
// The simulation starts at the model's rest shape and takes `steps_per_frame` MSM steps per
// frame interval; driven particles follow their observed positions inside their windows (holding
// the last observed position through occlusions; within an interval the target moves linearly
// from the previous frame's), everything else evolves under the model. The result
// has the layout of Recording::positions (frame-major, [(frame * N + id) * dim + axis]) with a
// value for every particle in every frame. Host code: allocates, throws std::runtime_error.
#pragma once

#include <memory>
#include <vector>

#include "pliant/host/msm_setup.hpp"
#include "pliant/host/recording.hpp"

namespace pliant::host {

/// Physics of one simulation. Defaults are the baseline of diagnosis-v1: elastic MSM, gravity
/// only when declared, pinned supports, one material, no damping, no plasticity.
struct ModelSettings {
  double msm_beta = 0.5;
  double msm_alpha = 1.0;
  int steps_per_frame = 1;            ///< MSM steps per frame interval, 1..max_steps_per_frame (core)
  std::vector<double> extra_gravity;  ///< undeclared body acceleration (empty: none), length_unit/s^2
  double velocity_damping = 0;        ///< 1/s
  double plastic_yield = 0;
  double plastic_creep = 0;  ///< 1/s; 0 = no plasticity
  double plastic_max = 1;
  double relaxation_fraction = 0;  ///< g1; 0 = no relaxation
  double relaxation_time_s = 1;
  double stiffening = 0;
  double support_friction = -1;  ///< mu; negative = pinned supports
  /// Per-particle msm_beta, particle_count values (empty: msm_beta everywhere). A cluster takes
  /// the mean over its members, so a stiffness map needs no cluster bookkeeping by the caller.
  std::vector<double> particle_beta;
};

/// One recording prepared for repeated simulation (model, observations, support normal).
class RecordingSimulator {
 public:
  /// `setup`: how the model is built (cluster radius, rest shape); the defaults are estimate's.
  explicit RecordingSimulator(const Recording& recording, const MsmSetupOptions& setup = MsmSetupOptions{});
  ~RecordingSimulator();
  RecordingSimulator(const RecordingSimulator&) = delete;
  RecordingSimulator& operator=(const RecordingSimulator&) = delete;

  /// Simulated positions for every frame (see top of file).
  std::vector<double> simulate(const ModelSettings& settings) const;

  const Recording& recording() const { return recording_; }
  /// Unit normal of the support (fixed particles) pointing into the object; zero without one.
  const std::vector<double>& support_normal() const { return support_normal_; }
  /// Rest shape the model uses (leading still frames averaged), particle_count * dimension.
  const std::vector<double>& rest() const;
  int cluster_count() const;

 private:
  struct Impl2;
  struct Impl3;
  const Recording& recording_;
  std::vector<double> support_normal_;
  std::unique_ptr<Impl2> impl2_;
  std::unique_ptr<Impl3> impl3_;
};

/// Mask [frames * particle_count]: 1 where the pair counts in a diagnosis rms (observed, and
/// not driven at that time).
std::vector<unsigned char> compared_pairs(const Recording& recording);

}  // namespace pliant::host
