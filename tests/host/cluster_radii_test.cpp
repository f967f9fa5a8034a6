// membership_radii: the cluster radii between two given ones at which the radius layout's
// clusters change, checked against pair counts made here.
#include "pliant/host/cluster_radii.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <algorithm>
#include <random>
#include <vector>

namespace {

// Pairs of particles within radius x spacing of each other: the radius layout's memberships.
int pairs_within(const std::vector<double>& rest, double spacing, double radius) {
  const std::size_t n = rest.size() / 2;
  int count = 0;
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = i + 1; j < n; ++j) {
      const double d = std::hypot(rest[2 * i] - rest[2 * j], rest[2 * i + 1] - rest[2 * j + 1]);
      if (d <= radius * spacing) ++count;
    }
  }
  return count;
}

std::vector<double> square_lattice(int nx, int ny, double spacing) {
  std::vector<double> rest;
  for (int y = 0; y < ny; ++y) {
    for (int x = 0; x < nx; ++x) {
      rest.push_back(x * spacing);
      rest.push_back(y * spacing);
    }
  }
  return rest;
}

TEST(MembershipRadii, ALatticeChangesOnlyAtItsFewDistances) {
  const std::vector<double> rest = square_lattice(6, 5, 0.01);
  // Between 1.3 and 1.75 only sqrt 2 is passed: the clusters are lo's or hi's, nothing between.
  EXPECT_TRUE(pliant::host::membership_radii(rest, 2, 0.01, 1.3, 1.75, 4).empty());
  // sqrt 2, 2 and sqrt 5 lie in (1.3, 2.3]: one radius between each consecutive two.
  const std::vector<double> radii = pliant::host::membership_radii(rest, 2, 0.01, 1.3, 2.3, 4);
  ASSERT_EQ(radii.size(), 2u);
  EXPECT_NEAR(radii[0], 0.5 * (std::sqrt(2.0) + 2.0), 1e-9);
  EXPECT_NEAR(radii[1], 0.5 * (2.0 + std::sqrt(5.0)), 1e-9);
}

TEST(MembershipRadii, AnIrregularBodyGetsRadiiWithClustersOfTheirOwn) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> jitter(-0.2, 0.2);
  std::vector<double> rest;
  for (int k = 0; k < 40; ++k) {  // a ring of two layers, irregular
    const double angle = 2 * M_PI * k / 20;
    const double radius = (k < 20 ? 3.0 : 4.0) + jitter(rng);
    rest.push_back(radius * std::cos(angle));
    rest.push_back(radius * std::sin(angle));
  }
  const double spacing = 0.95;
  const double lo = 1.3, hi = 2.2;
  for (int max_count : {1, 3, 50}) {
    const std::vector<double> radii = pliant::host::membership_radii(rest, 2, spacing, lo, hi, max_count);
    ASSERT_FALSE(radii.empty()) << max_count;
    EXPECT_LE(radii.size(), static_cast<std::size_t>(max_count));
    std::vector<int> counts{pairs_within(rest, spacing, lo)};
    for (std::size_t k = 0; k < radii.size(); ++k) {
      EXPECT_GT(radii[k], lo);
      EXPECT_LT(radii[k], hi);
      if (k > 0) {
        EXPECT_GT(radii[k], radii[k - 1]);
      }
      counts.push_back(pairs_within(rest, spacing, radii[k]));
    }
    counts.push_back(pairs_within(rest, spacing, hi));
    for (std::size_t k = 1; k < counts.size(); ++k) EXPECT_GT(counts[k], counts[k - 1]) << max_count << " " << k;
  }
  // With room for all, every membership between lo and hi is offered once.
  const std::vector<double> all = pliant::host::membership_radii(rest, 2, spacing, lo, hi, 1000, 0.0);
  std::vector<double> distances;
  for (std::size_t i = 0; i < 40; ++i) {
    for (std::size_t j = i + 1; j < 40; ++j) {
      const double d = std::hypot(rest[2 * i] - rest[2 * j], rest[2 * i + 1] - rest[2 * j + 1]) / spacing;
      if (d > lo && d <= hi) distances.push_back(d);
    }
  }
  std::sort(distances.begin(), distances.end());
  distances.erase(std::unique(distances.begin(), distances.end()), distances.end());
  EXPECT_EQ(all.size() + 1, distances.size());
}

TEST(MembershipRadii, NothingForDegenerateArguments) {
  const std::vector<double> rest = square_lattice(4, 4, 1.0);
  EXPECT_TRUE(pliant::host::membership_radii(rest, 2, 0.0, 1.3, 2.3, 4).empty());
  EXPECT_TRUE(pliant::host::membership_radii(rest, 2, 1.0, 2.3, 1.3, 4).empty());
  EXPECT_TRUE(pliant::host::membership_radii(rest, 2, 1.0, 1.3, 2.3, 0).empty());
  EXPECT_TRUE(pliant::host::membership_radii({}, 2, 1.0, 1.3, 2.3, 4).empty());
}

}  // namespace
