#include "pliant/host/diagnose/effects.hpp"

#include <algorithm>
#include <cmath>

namespace pliant::host {
namespace {

void apply_plasticity(const std::vector<double>& v, const EffectContext&, ModelSettings& s) {
  s.plastic_yield = v[0];
  s.plastic_creep = v[1];
  s.plastic_max = 1.0;
}

void apply_viscosity(const std::vector<double>& v, const EffectContext&, ModelSettings& s) {
  s.relaxation_fraction = v[0];
  s.relaxation_time_s = v[1];
}

// Searched as slip = 1 / (1 + mu) in [0, 1): 0 is the pin, 1 frictionless.
void apply_friction(const std::vector<double>& v, const EffectContext&, ModelSettings& s) {
  const double slip = std::clamp(v[0], 0.0, 0.999);
  s.support_friction = slip <= 0.0 ? -1.0 : 1.0 / slip - 1.0;
}

void apply_gravity(const std::vector<double>& v, const EffectContext& c, ModelSettings& s) {
  s.extra_gravity.assign(v.begin(), v.begin() + c.dimension);
}

void apply_heterogeneity(const std::vector<double>& v, const EffectContext& c, ModelSettings& s) {
  s.region = c.located;
  s.region_beta = v[0];
}

void apply_stiffening(const std::vector<double>& v, const EffectContext&, ModelSettings& s) { s.stiffening = v[0]; }

}  // namespace

std::vector<Effect> effect_catalogue(const EffectContext& context) {
  std::vector<Effect> effects;
  effects.push_back({"plasticity",
                     {{"yield", 0.0, 0.2, 0.0, true}, {"creep", 0.0, 40.0, 0.0, true}},
                     apply_plasticity,
                     "a yield/creep update of the rest shape (permanent set)",
                     "a long hold after release: a permanent set stays, viscous recovery continues"});
  effects.push_back({"viscosity",
                     {{"relaxation_fraction", 0.0, 0.9, 0.0, false}, {"relaxation_time_s", 0.05, 5.0, 0.05, true}},
                     apply_viscosity,
                     "viscoelastic relaxation of the rest shape (creep under load, slow recovery)",
                     "a second loading rate or a long hold: viscous effects change with rate and decay in time"});
  if (context.has_support) {
    effects.push_back({"friction",
                       {{"slip", 0.0, 1.0, 0.0, false}},
                       apply_friction,
                       "supports held by Coulomb friction on the support plane instead of pins",
                       "marking the support contacts: friction moves only them, and stops at load reversals"});
  }
  const double g = 40.0 * context.object_size;  // length_unit / s^2: a generous bound on a sag-causing body force
  std::vector<EffectParameter> gravity;
  const char* axes[] = {"g_x", "g_y", "g_z"};
  for (int d = 0; d < context.dimension; ++d) gravity.push_back({axes[d], -g, g, 0.0, false});
  effects.push_back({"gravity", gravity, apply_gravity, "an undeclared body force (gravity)",
                     "weighing the object or turning it over: a body force changes direction with orientation"});
  const int located = static_cast<int>(context.located.size());
  if (located >= 2 && located <= (context.particle_count * 2) / 3) {
    effects.push_back({"heterogeneity",
                       {{"region_msm_beta", 0.0, 1.0, -1.0, false}},
                       apply_heterogeneity,
                       "a region with its own msm_beta",
                       "pressing at a second site: a stiffer or softer region moves with the material"});
  }
  effects.push_back({"stiffening",
                     {{"stiffening", 0.0, 400.0, 0.0, true}},
                     apply_stiffening,
                     "msm_beta falling as strain grows (strain stiffening)",
                     "two load amplitudes: stiffening shows as a response that grows less than the load"});
  return effects;
}

}  // namespace pliant::host
