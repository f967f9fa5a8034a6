#include "pliant/host/diagnose/fem_effects.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace pliant::host {
namespace {

constexpr double kNoNull = std::numeric_limits<double>::quiet_NaN();

void apply_stiffening(const std::vector<double>& v, const FemEffectContext&, FemRunSettings& s) { s.stiffening = v[0]; }

// Force relaxation (g, tau), then in dynamic runs extra Rayleigh damping, in catalogue order.
void apply_relaxation(const std::vector<double>& v, const FemEffectContext&, FemRunSettings& s) {
  s.relaxation_fraction = v[0];
  s.relaxation_time_s = v[1];
}
void apply_damping(const std::vector<double>& v, const FemEffectContext&, FemRunSettings& s) {
  s.extra_rayleigh_beta = v[0];
}
void apply_relaxation_and_damping(const std::vector<double>& v, const FemEffectContext&, FemRunSettings& s) {
  s.relaxation_fraction = v[0];
  s.relaxation_time_s = v[1];
  s.extra_rayleigh_beta = v[2];
}

void apply_latency(const std::vector<double>& v, const FemEffectContext&, FemRunSettings& s) {
  s.wrench_latency_s = v[0];
}

void apply_gravity(const std::vector<double>& v, const FemEffectContext&, FemRunSettings& s) {
  s.extra_gravity_m_s2 = Eigen::Vector3d(v[0], v[1], v[2]);
}

// One factor per patch except the reference patch (factor 1); E scales them all.
void apply_heterogeneity(const std::vector<double>& v, const FemEffectContext& c, FemRunSettings& s) {
  std::vector<double> factor(static_cast<std::size_t>(c.patch_count), 1.0);
  std::size_t k = 0;
  for (int p = 0; p < c.patch_count; ++p) {
    if (p == c.reference_patch) continue;
    factor[static_cast<std::size_t>(p)] = v[k++];
  }
  s.element_factor.assign(c.element_patch.size(), 1.0);
  for (std::size_t e = 0; e < c.element_patch.size(); ++e)
    s.element_factor[e] = factor[static_cast<std::size_t>(c.element_patch[e])];
}

// Searched as slip = 1 / (1 + mu) in [0, 1]: 0 is the pin (the baseline), 1 frictionless.
void apply_friction(const std::vector<double>& v, const FemEffectContext&, FemRunSettings& s) {
  const double slip = std::clamp(v[0], 0.0, 1.0);
  s.support_friction = slip <= 0.0 ? -1.0 : 1.0 / slip - 1.0;
}

void apply_plasticity(const std::vector<double>& v, const FemEffectContext&, FemRunSettings& s) {
  s.plastic_yield = v[0];
  s.plastic_creep = v[1];
}

}  // namespace

std::vector<FemEffect> fem_effect_catalogue(const FemEffectContext& context) {
  std::vector<FemEffect> effects;
  const double peak = std::max(context.peak_strain, 0.01);
  const double dt = context.frame_interval_s > 0 ? context.frame_interval_s : 1.0;
  const double duration = std::max(context.duration_s, 2.0 * dt);

  // Stiffening: at the peak strain the modulus may reach 100 times its small-strain value.
  effects.push_back({"stiffening",
                     {{"stiffening", 0.0, std::log(100.0) / (peak * peak), 0.0, Scale::quadratic, true}},
                     apply_stiffening,
                     "a modulus that rises with strain, E exp(k eps^2) with eps the element's equivalent strain",
                     "two load amplitudes, or a second specimen height: stiffening follows strain, an indenter or "
                     "inclusion effect follows geometry"});

  // Viscosity.
  const EffectParameter fraction{"relaxation_fraction", 0.0, 2.0, 0.0, Scale::linear, true};
  const EffectParameter time{"relaxation_time_s", dt, std::max(duration, 1.01 * dt), kNoNull, Scale::logarithmic, true};
  const double omega = context.lowest_omega_rad_s > 0 ? context.lowest_omega_rad_s : 2.0 * 3.14159265358979323846 / dt;
  const EffectParameter damping{"rayleigh_beta", 0.0, 2.0 / omega, 0.0, Scale::quadratic, false};
  const std::string viscous_experiment =
      "a hold at constant strain and a second loading rate: relaxation decays in time and scales with rate, latency "
      "and stiffening do not";
  if (context.force_measured && !context.quasi_static) {
    effects.push_back({"viscosity",
                       {fraction, time, damping},
                       apply_relaxation_and_damping,
                       "viscoelastic relaxation of the force and extra stiffness-proportional damping",
                       viscous_experiment,
                       false,
                       true});
  } else if (context.force_measured) {
    effects.push_back(
        {"viscosity",
         {fraction, time},
         apply_relaxation,
         "viscoelastic relaxation (an instantaneous modulus (1 + g) E relaxing to E with time constant tau)",
         viscous_experiment,
         false,
         true});
  } else if (!context.quasi_static) {
    effects.push_back({"viscosity",
                       {damping},
                       apply_damping,
                       "extra stiffness-proportional (Rayleigh) damping",
                       viscous_experiment,
                       false,
                       true});
  }

  // Latency of the wrench stream.
  if (context.has_wrench) {
    const double bound = std::min(std::max(0.5, 5.0 * context.recording_interval_s), 0.25 * duration);
    effects.push_back({"latency",
                       {{"wrench_latency_s", -bound, bound, 0.0, Scale::linear, true}},
                       apply_latency,
                       "a time offset of the wrench stream against the positions",
                       "a step or a reversal of the drive: a latency shifts the force by the same time everywhere, "
                       "viscosity rounds it",
                       false,
                       true});
  }

  effects.push_back({"gravity",
                     {{"g_x", -20.0, 20.0, 0.0, Scale::linear, false},
                      {"g_y", -20.0, 20.0, 0.0, Scale::linear, false},
                      {"g_z", -20.0, 20.0, 0.0, Scale::linear, false}},
                     apply_gravity,
                     "an undeclared body force (gravity)",
                     "weighing the object or turning it over: a body force changes direction with orientation",
                     true});

  if (context.positions_compared && context.patch_count >= 2) {
    std::vector<EffectParameter> factors;
    for (int p = 0; p < context.patch_count; ++p) {
      if (p == context.reference_patch) continue;
      factors.push_back({"patch_" + std::to_string(p + 1) + "_factor", 0.1, 10.0, 1.0, Scale::logarithmic, false});
    }
    effects.push_back({"heterogeneity", factors, apply_heterogeneity,
                       "regions of different stiffness (a modulus factor per patch of elements)",
                       "pressing at a second site: a stiffer or softer region moves with the material"});
  }

  if (context.support_plane) {
    effects.push_back({"friction",
                       {{"slip", 0.0, 1.0, 0.0, Scale::linear, true}},
                       apply_friction,
                       "supports that slide on their plane with Coulomb friction instead of being pinned",
                       "marking the support contacts, or a lubricated or glued support: friction moves only them, "
                       "and they stop at load reversals",
                       false,
                       true});
  }

  if (context.unloads) {
    effects.push_back({"plasticity",
                       {{"yield", 0.0, peak, kNoNull, Scale::quadratic, true},
                        {"creep", 0.0, std::min(40.0, 2.0 / dt), 0.0, Scale::quadratic, true}},
                       apply_plasticity,
                       "a yield/creep update of the rest shape (permanent set)",
                       "a long hold after release: a permanent set stays, viscous recovery continues",
                       false,
                       true});
  }
  return effects;
}

}  // namespace pliant::host
