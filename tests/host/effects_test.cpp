// The diagnosis effect catalogue: unit-coordinate maps, the null of every effect, and the
// spatial patches the heterogeneity effect fits one msm_beta per.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <vector>

#include "pliant/host/diagnose/effects.hpp"

namespace pliant::host::test {
namespace {

// n_x x n_y grid at spacing 1, particle-major; row 0 first.
std::vector<double> grid(int nx, int ny) {
  std::vector<double> rest;
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      rest.push_back(i);
      rest.push_back(j);
    }
  }
  return rest;
}

TEST(EffectParameter, CoordinateInvertsEveryScale) {
  for (Scale scale : {Scale::linear, Scale::quadratic, Scale::logarithmic}) {
    EffectParameter p{"x", 0.05, 5.0, 0.0, scale, true};
    for (double u : {0.0, 0.1, 0.37, 0.5, 0.9, 1.0}) {
      EXPECT_NEAR(p.coordinate(p.value(u)), u, 1e-12) << static_cast<int>(scale) << " u " << u;
    }
    EXPECT_DOUBLE_EQ(p.value(0.0), 0.05);
    EXPECT_NEAR(p.value(1.0), 5.0, 1e-12);
    EXPECT_EQ(p.coordinate(-10.0), 0.0);  // clamped, never NaN
    EXPECT_EQ(p.coordinate(1e9), 1.0);
  }
  const EffectParameter log_scale{"tau", 0.05, 5.0, 0.0, Scale::logarithmic, true};
  EXPECT_NEAR(log_scale.value(0.5), 0.5, 1e-12);  // geometric mean of the range
}

TEST(EffectCatalogue, EveryEffectVanishesAtItsNull) {
  EffectContext context;
  context.dimension = 2;
  context.particle_count = 24;
  context.has_support = true;
  context.patches = spatial_patches(grid(6, 4), 2, 6, {0, 1, 2, 3, 4, 5});
  const std::vector<Effect> effects = effect_catalogue(context);
  std::set<std::string> names;
  for (const Effect& effect : effects) names.insert(effect.name);
  EXPECT_EQ(names,
            (std::set<std::string>{"plasticity", "viscosity", "friction", "gravity", "heterogeneity", "stiffening"}));

  const double beta = 0.43;
  ModelSettings baseline;
  baseline.msm_beta = beta;
  for (const Effect& effect : effects) {
    std::vector<double> values;
    for (const EffectParameter& p : effect.parameters) {
      // Parameters without a null of their own take any value; per-patch stiffness the bulk's.
      values.push_back(effect.replaces_beta ? beta : (std::isfinite(p.null_value) ? p.null_value : p.value(0.7)));
    }
    ModelSettings s;
    s.msm_beta = beta;
    effect.apply(values, context, s);
    EXPECT_EQ(s.plastic_creep, 0.0) << effect.name;
    EXPECT_EQ(s.velocity_damping, 0.0) << effect.name;
    EXPECT_EQ(s.relaxation_fraction, 0.0) << effect.name;
    EXPECT_LT(s.support_friction, 0.0) << effect.name;  // pinned
    for (double g : s.extra_gravity) EXPECT_EQ(g, 0.0) << effect.name;
    EXPECT_EQ(s.stiffening, 0.0) << effect.name;
    for (double b : s.particle_beta) EXPECT_EQ(b, beta) << effect.name;
  }
}

TEST(EffectCatalogue, FrictionNeedsASupportAndHeterogeneityPatches) {
  EffectContext context;
  context.dimension = 3;
  context.particle_count = 10;
  const std::vector<Effect> effects = effect_catalogue(context);
  for (const Effect& effect : effects) {
    EXPECT_NE(effect.name, "friction");
    EXPECT_NE(effect.name, "heterogeneity");
    if (effect.name == "gravity") {
      EXPECT_EQ(effect.parameters.size(), 3u);
    }
  }
}

TEST(SpatialPatches, CoverEveryParticleOnceAndKeepSupportsWithTheirNeighbours) {
  const std::vector<double> rest = grid(8, 6);  // 48 particles
  const std::vector<int> supports = {0, 1, 2, 3, 4, 5, 6, 7};
  const auto patches = spatial_patches(rest, 2, 8, supports);
  ASSERT_GE(patches.size(), 2u);
  EXPECT_LE(patches.size(), 5u);  // 40 free particles / 8
  std::vector<int> seen;
  for (const auto& patch : patches) {
    EXPECT_FALSE(patch.empty());
    EXPECT_TRUE(std::is_sorted(patch.begin(), patch.end()));
    seen.insert(seen.end(), patch.begin(), patch.end());
  }
  std::sort(seen.begin(), seen.end());
  std::vector<int> all(48);
  for (int i = 0; i < 48; ++i) all[static_cast<std::size_t>(i)] = i;
  EXPECT_EQ(seen, all);
  // A support shares its patch with the free particle right above it.
  for (int s : supports) {
    for (const auto& patch : patches) {
      const bool has_support = std::find(patch.begin(), patch.end(), s) != patch.end();
      const bool has_above = std::find(patch.begin(), patch.end(), s + 8) != patch.end();
      if (has_support) {
        EXPECT_TRUE(has_above) << "support " << s;
      }
    }
  }
  // Patches are compact: no patch spans the whole grid.
  for (const auto& patch : patches) {
    double lo = 1e9;
    double hi = -1e9;
    for (int id : patch) {
      lo = std::min(lo, rest[static_cast<std::size_t>(id * 2)]);
      hi = std::max(hi, rest[static_cast<std::size_t>(id * 2)]);
    }
    EXPECT_LT(hi - lo, 7.0);
  }
  EXPECT_EQ(spatial_patches(rest, 2, 8, supports), patches);  // deterministic
}

TEST(SpatialPatches, TooFewFreeParticlesGiveNoPatches) {
  EXPECT_TRUE(spatial_patches(grid(2, 2), 2, 6, {0, 1}).empty());
  EXPECT_TRUE(spatial_patches({}, 3, 6, {}).empty());
  EXPECT_EQ(spatial_patches(grid(2, 2), 2, 6, {}).size(), 2u);
}

}  // namespace
}  // namespace pliant::host::test
