// Model construction: cluster layouts, the exact median spacing, and every rejected input.
#include "pliant/core/msm_model.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "msm_fixture.hpp"

namespace {

using pliant::Status;
using pliant::test::lattice;
using Fixture2 = pliant::test::MsmFixture<2, double>;

template <int Dim>
pliant::MsmModelConfig<Dim, double> config_over(const std::vector<double>& rest) {
  pliant::MsmModelConfig<Dim, double> c;
  c.particle_count = static_cast<int>(rest.size()) / Dim;
  c.rest_positions = rest.data();
  return c;
}

int members_of(const pliant::MsmModel<2, double>& m, int c) { return m.cluster_begin[c + 1] - m.cluster_begin[c]; }
int members_of(const pliant::MsmModel<3, double>& m, int c) { return m.cluster_begin[c + 1] - m.cluster_begin[c]; }

TEST(MsmModel, DefaultClustersOn2dLatticeHoldTheEightNeighbours) {
  const auto rest = lattice<2, double>(8, 4, 1, 100.0);
  pliant::test::MsmFixture<2, double> f(config_over<2>(rest));
  ASSERT_EQ(f.status, Status::ok);
  EXPECT_EQ(f.model.cluster_count, 32);
  EXPECT_DOUBLE_EQ(f.model.spacing, 100.0);
  EXPECT_EQ(members_of(f.model, 1 * 8 + 3), 9);  // interior: itself, 4 edge and 4 diagonal neighbours
  EXPECT_EQ(members_of(f.model, 0), 4);          // corner
}

TEST(MsmModel, DefaultClustersOn3dLatticeHoldNineteen) {
  const auto rest = lattice<3, double>(4, 4, 4, 0.01);
  pliant::test::MsmFixture<3, double> f(config_over<3>(rest));
  ASSERT_EQ(f.status, Status::ok);
  const int interior = (1 * 4 + 1) * 4 + 1;
  EXPECT_EQ(members_of(f.model, interior), 19);  // 6 faces + 12 edges (sqrt 2 < 1.5 < sqrt 3) + itself
}

TEST(MsmModel, PaperGridBlocksAreThreeByTwo) {
  const auto rest = lattice<2, double>(8, 4, 1, 100.0);
  auto c = config_over<2>(rest);
  c.clusters.layout = pliant::ClusterLayout::grid_blocks;
  c.clusters.grid_cols = 8;
  c.clusters.grid_rows = 4;
  pliant::test::MsmFixture<2, double> f(c);
  ASSERT_EQ(f.status, Status::ok);
  EXPECT_EQ(f.model.cluster_count, 6 * 3);
  for (int k = 0; k < f.model.cluster_count; ++k) EXPECT_EQ(members_of(f.model, k), 6);
  // First block: columns 0..2 of rows 0..1.
  const int expected[] = {0, 1, 2, 8, 9, 10};
  for (int m = 0; m < 6; ++m) EXPECT_EQ(f.model.members[m], expected[m]);
}

TEST(MsmModel, KNearestHoldsKPlusOne) {
  const auto rest = lattice<2, double>(6, 5, 1, 1.0);
  auto c = config_over<2>(rest);
  c.clusters.layout = pliant::ClusterLayout::k_nearest;
  c.clusters.k = 5;
  pliant::test::MsmFixture<2, double> f(c);
  ASSERT_EQ(f.status, Status::ok);
  for (int k = 0; k < f.model.cluster_count; ++k) EXPECT_EQ(members_of(f.model, k), 6);
}

TEST(MsmModel, MedianSpacingIsExactOnScatteredPoints) {
  for (int n : {2, 3, 101, 500}) {
    std::mt19937 rng(static_cast<unsigned>(n));
    std::uniform_real_distribution<double> u(0.0, 10.0);
    std::vector<double> rest(static_cast<std::size_t>(3 * n));
    for (auto& v : rest) v = u(rng);
    std::vector<double> nearest;
    for (int i = 0; i < n; ++i) {
      double best = 1e300;
      for (int j = 0; j < n; ++j) {
        if (i == j) continue;
        const Eigen::Map<const Eigen::Vector3d> a(&rest[static_cast<std::size_t>(3 * i)]);
        const Eigen::Map<const Eigen::Vector3d> b(&rest[static_cast<std::size_t>(3 * j)]);
        const Eigen::Vector3d d = a - b;
        best = std::min(best, d.norm());
      }
      nearest.push_back(best);
    }
    std::sort(nearest.begin(), nearest.end());
    auto c = config_over<3>(rest);
    c.clusters.radius_factor = 3.0;  // keep every particle in some cluster
    pliant::test::MsmFixture<3, double> f(c);
    if (f.status == Status::degenerate_cluster) continue;  // an isolated point: legal rejection
    ASSERT_EQ(f.status, Status::ok) << n;
    EXPECT_NEAR(f.model.spacing, nearest[static_cast<std::size_t>((n - 1) / 2)], 1e-12) << n;
  }
}

TEST(MsmModel, DrivenMassFactorScalesOnlyDrivableParticles) {
  const auto rest = lattice<2, double>(4, 4, 1, 1.0);
  auto c = config_over<2>(rest);
  const int tool = 13;
  c.drivable_ids = &tool;
  c.drivable_count = 1;
  c.driven_mass_factor = 10.0;
  pliant::test::MsmFixture<2, double> f(c);
  ASSERT_EQ(f.status, Status::ok);
  EXPECT_DOUBLE_EQ(f.model.mass[tool], 10.0);
  EXPECT_DOUBLE_EQ(f.model.mass[12], 1.0);
}

TEST(MsmModel, AParticleJustBeyondTheRadiusJoinsItsNearestNeighbours) {
  // A 4 x 3 lattice of spacing 1 (radius 1.5) and one particle 2 from the corner (0, 0): no
  // neighbour within the radius, its nearest within twice it. Its cluster holds the particles
  // within 1.5 x 2 = 3 of it; no other cluster holds it.
  auto rest = lattice<2, double>(4, 3, 1, 1.0);
  rest.push_back(-2.0);
  rest.push_back(0.0);
  pliant::test::MsmFixture<2, double> f(config_over<2>(rest));
  ASSERT_EQ(f.status, Status::ok);
  const int sparse = 12;
  std::vector<int> members(f.model.members + f.model.cluster_begin[sparse],
                           f.model.members + f.model.cluster_begin[sparse + 1]);
  EXPECT_EQ(members, (std::vector<int>{0, 1, 4, 8, 12}));  // (0,0), (1,0), (0,1), (0,2) and itself
  EXPECT_EQ(f.model.particle_cluster_begin[sparse + 1] - f.model.particle_cluster_begin[sparse], 1);
}

TEST(MsmModel, RejectsBadInputWithAStatus) {
  auto rest = lattice<2, double>(4, 3, 1, 1.0);
  {  // zero mass
    std::vector<double> masses(12, 1.0);
    masses[5] = 0.0;
    auto c = config_over<2>(rest);
    c.masses = masses.data();
    EXPECT_EQ(Fixture2(c).status, Status::invalid_mass);
  }
  {  // NaN rest position
    auto bad = rest;
    bad[7] = std::nan("");
    EXPECT_EQ(Fixture2(config_over<2>(bad)).status, Status::non_finite_input);
  }
  {  // duplicate rest positions
    auto dup = rest;
    dup[2] = dup[0];
    dup[3] = dup[1];
    EXPECT_EQ(Fixture2(config_over<2>(dup)).status, Status::duplicate_rest_positions);
  }
  {  // a particle far from all others forms a one-member cluster: no rotation defined
    auto lonely = rest;
    lonely.push_back(100.0);
    lonely.push_back(100.0);
    EXPECT_EQ(Fixture2(config_over<2>(lonely)).status, Status::degenerate_cluster);
  }
  {  // a single particle
    std::vector<double> one = {0.0, 0.0};
    EXPECT_EQ(Fixture2(config_over<2>(one)).status, Status::degenerate_cluster);
  }
  {  // grid blocks that do not match the particle count
    auto c = config_over<2>(rest);
    c.clusters.layout = pliant::ClusterLayout::grid_blocks;
    c.clusters.grid_cols = 5;
    c.clusters.grid_rows = 3;
    EXPECT_EQ(Fixture2(c).status, Status::invalid_argument);
  }
  {  // drivable id out of range
    auto c = config_over<2>(rest);
    const int id = 12;
    c.drivable_ids = &id;
    c.drivable_count = 1;
    EXPECT_EQ(Fixture2(c).status, Status::invalid_argument);
  }
  {  // no particles
    pliant::MsmModelConfig<2, double> c;
    EXPECT_EQ(pliant::msm_model_workspace_size(c), 0u);
    EXPECT_EQ(Fixture2(c).status, Status::invalid_argument);
  }
}

TEST(MsmModel, TooSmallBlockIsCapacityExceeded) {
  const auto rest = lattice<2, double>(4, 4, 1, 1.0);
  const auto c = config_over<2>(rest);
  const std::size_t need = pliant::msm_model_workspace_size(c);
  ASSERT_GT(need, 0u);
  std::vector<unsigned char> block(need / 2);
  pliant::Arena arena(block.data(), block.size());
  pliant::MsmModel<2, double> model;
  EXPECT_EQ(pliant::msm_model_init(arena, c, model), Status::capacity_exceeded);
  EXPECT_FALSE(model.initialized());
}

}  // namespace
