// The catalogue of physics `diagnose` can add to the elastic MSM baseline.
//
// Every effect is a parametric extension that reduces exactly to the baseline at its null
// value (DIAGNOSIS.md principle 1). Parameters are searched in a unit coordinate u in [0, 1]
// mapped to physical values; `null_value` is the physical value that switches the effect off.
// Host code: allocates.
#pragma once

#include <string>
#include <vector>

#include "pliant/host/diagnose/diagnosis.hpp"
#include "pliant/host/diagnose/model_run.hpp"

namespace pliant::host {

struct EffectParameter {
  std::string name;      ///< key in the JSON ("yield", "creep", "mu", "g_x", ...)
  double lower = 0;      ///< physical value at u = 0
  double upper = 1;      ///< physical value at u = 1
  double null_value = 0; ///< value at which the effect vanishes
  bool quadratic = false;  ///< value = lower + (upper - lower) u^2: finer steps near `lower`
  double value(double u) const { return lower + (upper - lower) * (quadratic ? u * u : u); }
};

/// What the effects need to know about the recording and the located mismatch.
struct EffectContext {
  int dimension = 2;
  double object_size = 1;          ///< largest extent of the rest shape, length_unit
  bool has_support = false;        ///< fixed particles span a support line / plane
  std::vector<int> located;        ///< particles where the residual concentrates
  int particle_count = 0;
};

struct Effect {
  std::string name;  ///< word of the diagnosis-v1 effect table
  std::vector<EffectParameter> parameters;
  /// Sets the effect's physics on `settings` from physical parameter values.
  void (*apply)(const std::vector<double>& values, const EffectContext& context, ModelSettings& settings) = nullptr;
  std::string physics;     ///< for explanations: what was modelled
  std::string experiment;  ///< the experiment that tells it apart from its look-alikes
};

/// The effects that can apply to this recording (friction needs a support, heterogeneity a
/// located region that is not the whole object). Latency is not offered: the MSM baseline
/// takes no wrench or gripper stream as input, so there is no second clock to shift.
std::vector<Effect> effect_catalogue(const EffectContext& context);

}  // namespace pliant::host
