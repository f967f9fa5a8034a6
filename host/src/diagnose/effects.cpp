#include "pliant/host/diagnose/effects.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace pliant::host {
namespace {

constexpr double kNoNull = std::numeric_limits<double>::quiet_NaN();

void apply_plasticity(const std::vector<double>& v, const EffectContext&, ModelSettings& s) {
  s.plastic_yield = v[0];
  s.plastic_creep = v[1];
  s.plastic_max = 1.0;
}

void apply_viscosity(const std::vector<double>& v, const EffectContext&, ModelSettings& s) {
  s.velocity_damping = v[0];
  s.relaxation_fraction = v[1];
  s.relaxation_time_s = v[2];
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
  s.particle_beta.assign(static_cast<std::size_t>(c.particle_count), s.msm_beta);
  for (std::size_t p = 0; p < c.patches.size(); ++p) {
    for (int id : c.patches[p]) s.particle_beta[static_cast<std::size_t>(id)] = v[p];
  }
}

void apply_stiffening(const std::vector<double>& v, const EffectContext&, ModelSettings& s) { s.stiffening = v[0]; }

double squared_distance(const std::vector<double>& rest, int dim, int i, const std::vector<double>& centre) {
  double sum = 0;
  for (int d = 0; d < dim; ++d) {
    const double delta = rest[static_cast<std::size_t>(i * dim + d)] - centre[static_cast<std::size_t>(d)];
    sum += delta * delta;
  }
  return sum;
}

}  // namespace

double EffectParameter::coordinate(double physical) const {
  double u = 0;
  switch (scale) {
    case Scale::quadratic:
      u = upper > lower ? std::sqrt(std::max(0.0, (physical - lower) / (upper - lower))) : 0.0;
      break;
    case Scale::logarithmic:
      u = physical > 0 && upper > lower ? std::log(physical / lower) / std::log(upper / lower) : 0.0;
      break;
    case Scale::linear: u = upper > lower ? (physical - lower) / (upper - lower) : 0.0; break;
  }
  return std::isfinite(u) ? std::clamp(u, 0.0, 1.0) : 0.0;
}

std::vector<std::vector<int>> spatial_patches(const std::vector<double>& all_rest, int dimension, int target_size,
                                              const std::vector<int>& attached) {
  const int total = dimension > 0 ? static_cast<int>(all_rest.size()) / dimension : 0;
  // Patches are made of the free particles; attached ones join their nearest free particle's.
  std::vector<unsigned char> is_attached(static_cast<std::size_t>(std::max(total, 0)), 0);
  for (int id : attached) {
    if (id >= 0 && id < total) is_attached[static_cast<std::size_t>(id)] = 1;
  }
  std::vector<int> free_ids;
  std::vector<double> rest;
  for (int i = 0; i < total; ++i) {
    if (is_attached[static_cast<std::size_t>(i)] != 0) continue;
    free_ids.push_back(i);
    rest.insert(rest.end(), all_rest.begin() + i * dimension, all_rest.begin() + (i + 1) * dimension);
  }
  const int n = static_cast<int>(free_ids.size());
  if (n < 4) return {};
  const int k = std::clamp(n / std::max(target_size, 2), 2, n / 2);
  // Farthest-point seeds from the first particle, then Lloyd iterations: deterministic.
  std::vector<std::vector<double>> centres;
  auto position = [&](int i) {
    return std::vector<double>(rest.begin() + i * dimension, rest.begin() + (i + 1) * dimension);
  };
  std::vector<double> nearest(static_cast<std::size_t>(n), std::numeric_limits<double>::infinity());
  int next = 0;
  for (int c = 0; c < k; ++c) {
    centres.push_back(position(next));
    int farthest = 0;
    for (int i = 0; i < n; ++i) {
      nearest[static_cast<std::size_t>(i)] =
          std::min(nearest[static_cast<std::size_t>(i)], squared_distance(rest, dimension, i, centres.back()));
      if (nearest[static_cast<std::size_t>(i)] > nearest[static_cast<std::size_t>(farthest)]) farthest = i;
    }
    next = farthest;
  }
  std::vector<int> label(static_cast<std::size_t>(n), -1);
  for (int iteration = 0; iteration < 50; ++iteration) {
    bool changed = false;
    for (int i = 0; i < n; ++i) {
      int best = 0;
      for (int c = 1; c < k; ++c) {
        if (squared_distance(rest, dimension, i, centres[static_cast<std::size_t>(c)]) <
            squared_distance(rest, dimension, i, centres[static_cast<std::size_t>(best)])) {
          best = c;
        }
      }
      if (label[static_cast<std::size_t>(i)] != best) changed = true;
      label[static_cast<std::size_t>(i)] = best;
    }
    if (!changed) break;
    for (int c = 0; c < k; ++c) {
      std::vector<double> sum(static_cast<std::size_t>(dimension), 0.0);
      int count = 0;
      for (int i = 0; i < n; ++i) {
        if (label[static_cast<std::size_t>(i)] != c) continue;
        for (int d = 0; d < dimension; ++d)
          sum[static_cast<std::size_t>(d)] += rest[static_cast<std::size_t>(i * dimension + d)];
        ++count;
      }
      if (count == 0) continue;
      for (double& v : sum) v /= count;
      centres[static_cast<std::size_t>(c)] = sum;
    }
  }
  std::vector<std::vector<int>> patches(static_cast<std::size_t>(k));
  for (int i = 0; i < n; ++i)
    patches[static_cast<std::size_t>(label[static_cast<std::size_t>(i)])].push_back(
        free_ids[static_cast<std::size_t>(i)]);
  for (int a = 0; a < total; ++a) {
    if (is_attached[static_cast<std::size_t>(a)] == 0) continue;
    const std::vector<double> at(all_rest.begin() + a * dimension, all_rest.begin() + (a + 1) * dimension);
    int nearest_free = 0;
    for (int i = 1; i < n; ++i) {
      if (squared_distance(rest, dimension, i, at) < squared_distance(rest, dimension, nearest_free, at))
        nearest_free = i;
    }
    patches[static_cast<std::size_t>(label[static_cast<std::size_t>(nearest_free)])].push_back(a);
  }
  for (std::vector<int>& patch : patches) std::sort(patch.begin(), patch.end());
  patches.erase(std::remove_if(patches.begin(), patches.end(), [](const std::vector<int>& p) { return p.empty(); }),
                patches.end());
  return patches;
}

std::vector<Effect> effect_catalogue(const EffectContext& context) {
  std::vector<Effect> effects;
  effects.push_back(
      {"plasticity",
       {{"yield", 0.0, 0.2, kNoNull, Scale::quadratic, true}, {"creep", 0.0, 40.0, 0.0, Scale::quadratic, true}},
       apply_plasticity,
       "a yield/creep update of the rest shape (permanent set)",
       "a long hold after release: a permanent set stays, viscous recovery continues"});
  effects.push_back({"viscosity",
                     {{"damping", 0.0, 20.0, 0.0, Scale::linear, false},
                      {"relaxation_fraction", 0.0, 0.9, 0.0, Scale::linear, true},
                      {"relaxation_time_s", 0.05, 5.0, kNoNull, Scale::logarithmic, true}},
                     apply_viscosity,
                     "viscous dissipation (velocity damping, and relaxation of the rest shape toward the load)",
                     "a second loading rate or a long hold: viscous effects change with rate and decay in time"});
  if (context.has_support) {
    effects.push_back({"friction",
                       {{"slip", 0.0, 1.0, 0.0, Scale::linear, true}},
                       apply_friction,
                       "supports held by Coulomb friction on the support plane instead of pins",
                       "marking the support contacts: friction moves only them, and stops at load reversals"});
  }
  const double g = 40.0 * context.object_size;  // length_unit / s^2: a generous bound on a sag-causing body force
  std::vector<EffectParameter> gravity;
  const char* axes[] = {"g_x", "g_y", "g_z"};
  for (int d = 0; d < context.dimension; ++d) gravity.push_back({axes[d], -g, g, 0.0, Scale::linear, false});
  effects.push_back({"gravity", gravity, apply_gravity, "an undeclared body force (gravity)",
                     "weighing the object or turning it over: a body force changes direction with orientation"});
  if (context.patches.size() >= 2) {
    std::vector<EffectParameter> patches;
    for (std::size_t p = 0; p < context.patches.size(); ++p) {
      patches.push_back({"patch_" + std::to_string(p + 1) + "_msm_beta", 0.0, 1.0, kNoNull, Scale::linear, false});
    }
    Effect heterogeneity{"heterogeneity", patches, apply_heterogeneity,
                         "regions of different stiffness (msm_beta per patch of the object)",
                         "pressing at a second site: a stiffer or softer region moves with the material"};
    heterogeneity.replaces_beta = true;
    effects.push_back(heterogeneity);
  }
  effects.push_back({"stiffening",
                     {{"stiffening", 0.0, 400.0, 0.0, Scale::quadratic, true}},
                     apply_stiffening,
                     "msm_beta falling as strain grows (strain stiffening)",
                     "two load amplitudes: stiffening shows as a response that grows less than the load"});
  return effects;
}

}  // namespace pliant::host
