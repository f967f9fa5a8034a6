// The catalogue of physics `diagnose` can add to the elastic MSM baseline.
//
// Every effect is a parametric extension that reduces exactly to the baseline at its null
// value (DIAGNOSIS.md principle 1). Parameters are searched in a unit coordinate u in [0, 1]
// mapped to physical values; `null_value` is the physical value that switches the effect off.
// Host code: allocates.
#pragma once

#include <cmath>
#include <string>
#include <vector>

#include "pliant/host/diagnose/diagnosis.hpp"
#include "pliant/host/diagnose/model_run.hpp"

namespace pliant::host {

/// How a unit search coordinate u in [0, 1] maps to a physical value.
enum class Scale {
  linear,       ///< lower + (upper - lower) u
  quadratic,    ///< lower + (upper - lower) u^2: finer steps near `lower`
  logarithmic,  ///< lower (upper / lower)^u; needs 0 < lower < upper
};

struct EffectParameter {
  std::string name;  ///< key in the JSON ("yield", "creep", "slip", "g_x", ...)
  double lower = 0;  ///< physical value at u = 0
  double upper = 1;  ///< physical value at u = 1
  /// Value at which the effect vanishes; NaN when the parameter has no null of its own (a time
  /// constant, a yield strain, a per-patch stiffness) and is not tested against one.
  double null_value = 0;
  Scale scale = Scale::linear;
  /// True: the fit starts from a grid over this coordinate (responses that are flat near the
  /// null, like a yield above every strain). False: the fit starts at the null and relies on
  /// the gradient there (body forces, per-region stiffness).
  bool scanned = true;
  double value(double u) const {
    switch (scale) {
      case Scale::quadratic: return lower + (upper - lower) * u * u;
      case Scale::logarithmic: return lower * std::pow(upper / lower, u);
      case Scale::linear: break;
    }
    return lower + (upper - lower) * u;
  }
  /// Inverse of value(), clamped to [0, 1].
  double coordinate(double physical) const;
};

/// What the effects need to know about the recording and the located mismatch.
struct EffectContext {
  int dimension = 2;
  double object_size = 1;    ///< largest extent of the rest shape, length_unit
  bool has_support = false;  ///< fixed particles span a support line / plane
  std::vector<int> located;  ///< particles where the residual concentrates
  int particle_count = 0;
  /// Spatial patches of the rest shape (each a list of particle ids; together every particle
  /// once): the control regions of the heterogeneity effect.
  std::vector<std::vector<int>> patches;
};

struct Effect {
  std::string name;  ///< word of the diagnosis-v1 effect table
  std::vector<EffectParameter> parameters;
  /// Sets the effect's physics on `settings` from physical parameter values.
  void (*apply)(const std::vector<double>& values, const EffectContext& context, ModelSettings& settings) = nullptr;
  std::string physics;     ///< for explanations: what was modelled
  std::string experiment;  ///< the experiment that tells it apart from its look-alikes
  /// True when the parameters set msm_beta everywhere themselves (per-patch stiffness), so the
  /// global msm_beta is not fitted alongside them.
  bool replaces_beta = false;
};

/// Patches of about `target_size` free particles by k-means on the rest positions
/// (particle-major, `dimension` values each), deterministic; at least 2 patches when there
/// are at least 4 free particles, none otherwise. The `attached` particles (fixed supports,
/// whose own stiffness the motion barely shows) join the patch of their nearest free particle.
/// Every particle is in exactly one patch; ids ascending within a patch.
std::vector<std::vector<int>> spatial_patches(const std::vector<double>& rest, int dimension, int target_size,
                                              const std::vector<int>& attached);

/// The effects that can apply to this recording (friction needs a support, heterogeneity at
/// least two patches). Latency is not offered: the MSM baseline
/// takes no wrench or gripper stream as input, so there is no second clock to shift.
std::vector<Effect> effect_catalogue(const EffectContext& context);

}  // namespace pliant::host
