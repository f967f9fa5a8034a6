// The catalogue of physics `pliant diagnose --model fem` can add to the linear FEM baseline
// (the FEM counterpart of effects.hpp; docs/diagnose.md, section "--model fem").
//
// Every effect reduces exactly to the baseline at its null value (DIAGNOSIS.md principle 1).
// Parameters use EffectParameter of effects.hpp: a unit search coordinate mapped to physical
// values, a null (NaN when the parameter has none) and whether the fit starts from a grid.
// Which effects are offered depends on what the recording can show (FemEffectContext):
// - stiffening: always;
// - viscosity: relaxation of the force when a wrench is measured; extra Rayleigh damping in
//   dynamic runs; nothing to act on otherwise (quasi-static, no measured force);
// - latency: when there is a wrench stream;
// - gravity: always (an undeclared body force: sag, or weight in the measured force);
// - heterogeneity: only when free node positions are compared (one net force cannot tell
//   where a region is) and there are at least two patches;
// - friction: when the fixed nodes lie on one plane (FemRecordingSimulator::has_support_plane):
//   the supports slide on it with Coulomb friction instead of being pinned;
// - plasticity: only when the recording unloads (a permanent set shows after unloading; during
//   monotonic loading it is indistinguishable from softening).
// Host code: allocates.
#pragma once

#include <string>
#include <vector>

#include "pliant/host/diagnose/effects.hpp"
#include "pliant/host/diagnose/fem_model_run.hpp"

namespace pliant::host {

struct FemEffectContext {
  bool quasi_static = true;
  bool force_measured = false;  ///< some frame compares the simulated force with the wrench
  bool has_wrench = false;
  bool positions_compared = false;  ///< some free node is observed
  bool unloads = false;             ///< the drive or load falls back after its peak
  bool support_plane = false;       ///< the fixed nodes lie on one plane
  double frame_interval_s = 1;      ///< mean interval between solved frames
  double recording_interval_s = 1;  ///< mean interval between the recording's frames
  double duration_s = 1;
  double peak_strain = 0.1;        ///< largest element strain of the baseline run
  double lowest_omega_rad_s = 0;   ///< of the baseline (0: unknown)
  std::vector<int> element_patch;  ///< patch index per element (heterogeneity)
  int patch_count = 0;
  int reference_patch = 0;  ///< the patch whose factor stays 1 (the largest)
};

struct FemEffect {
  std::string name;  ///< word of the diagnosis-v1 effect table
  std::vector<EffectParameter> parameters;
  void (*apply)(const std::vector<double>& values, const FemEffectContext& context, FemRunSettings& settings) = nullptr;
  std::string physics;     ///< for explanations: what was modelled
  std::string experiment;  ///< the experiment that tells it apart from its look-alikes
  /// The parameters are an extra body acceleration (x, y, z in m/s^2). E is profiled in closed
  /// form only at a fixed ratio of body acceleration to E (fem_diagnose.cpp).
  bool body_force = false;
  /// The simulated output at a frame depends on earlier frames (relaxation, latency, plastic
  /// creep): fitted on runs of all solved frames, never on the fitting frames alone.
  bool history = false;
};

std::vector<FemEffect> fem_effect_catalogue(const FemEffectContext& context);

}  // namespace pliant::host
