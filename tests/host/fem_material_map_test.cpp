// MaterialMap and place_control_points: one point gives a uniform field, weights are a
// partition of unity, values stay within the control values, well-separated points own their
// regions, the kernel width rule, deterministic placement, and refusals.
#include "pliant/host/fem/material_map.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "pliant/host/fem/fem_box_mesh.hpp"

namespace {

using pliant::host::TetMesh;
using pliant::host::fem::element_centroids;
using pliant::host::fem::make_box_tet_mesh;
using pliant::host::fem::MaterialMap;
using pliant::host::fem::MaterialMapOptions;
using pliant::host::fem::place_control_points;

TetMesh bar() { return make_box_tet_mesh({0.4, 0.05, 0.05}, {20, 5, 5}); }

std::vector<Eigen::Vector3d> axis_points(int k) {
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < k; ++i) points.emplace_back(0.4 * (i + 0.5) / k, 0.025, 0.025);
  return points;
}

TEST(FemMaterialMap, OneControlPointGivesAUniformField) {
  const MaterialMap map(bar(), {Eigen::Vector3d(0.1, 0.0, 0.3)});
  EXPECT_EQ(map.control_point_count(), 1);
  EXPECT_EQ(map.element_count(), 3000);
  const Eigen::VectorXd e = map.element_values({6.8e5});
  EXPECT_NEAR(e.minCoeff(), 6.8e5, 1e-9 * 6.8e5);
  EXPECT_NEAR(e.maxCoeff(), 6.8e5, 1e-9 * 6.8e5);
}

TEST(FemMaterialMap, WeightsAreAPartitionOfUnityAndValuesStayInBounds) {
  const MaterialMap map(bar(), axis_points(8));
  const Eigen::MatrixXd& w = map.weights();
  ASSERT_EQ(w.rows(), 3000);
  ASSERT_EQ(w.cols(), 8);
  EXPECT_GE(w.minCoeff(), 0.0);
  EXPECT_LT((w.rowwise().sum().array() - 1.0).abs().maxCoeff(), 1e-12);
  const std::vector<double> values = {1e5, 1e6, 1e4, 6.8e5, 2e6, 7e4, 1e7, 3e4};
  const Eigen::VectorXd e = map.element_values(values);
  EXPECT_GE(e.minCoeff(), 1e4);
  EXPECT_LE(e.maxCoeff(), 1e7);
  // log E is the weighted mean of the log values.
  for (Eigen::Index row : {Eigen::Index{0}, Eigen::Index{1234}, Eigen::Index{2999}}) {
    double expected = 0;
    for (int i = 0; i < 8; ++i) expected += w(row, i) * std::log(values[static_cast<std::size_t>(i)]);
    EXPECT_NEAR(std::log(e(row)), expected, 1e-12);
  }
}

TEST(FemMaterialMap, WellSeparatedPointsOwnTheirRegions) {
  const MaterialMap map(bar(), axis_points(8));
  // Automatic width: a third of the nearest-neighbour spacing (0.05 m).
  EXPECT_NEAR(map.kernel_width_m(), 0.05 / 3.0, 1e-12);
  const std::vector<double> values = {1e5, 1e6, 1e4, 6.8e5, 2e6, 7e4, 1e7, 3e4};
  const Eigen::VectorXd e = map.element_values(values);
  const std::vector<Eigen::Vector3d> centroids = element_centroids(bar());
  const std::vector<int> owner = map.dominant_control_point();
  const Eigen::MatrixXd& w = map.weights();
  for (std::size_t el = 0; el < centroids.size(); ++el) {
    const double x = centroids[el].x();
    const double cell = x / 0.05;
    if (std::abs(cell - std::round(cell)) < 1e-6) continue;  // on a midplane between two points: a tie
    const int nearest = std::clamp(static_cast<int>(cell), 0, 7);
    EXPECT_EQ(owner[el], nearest) << "element " << el << " x " << x;
    // Within an eighth of the spacing of its point an element takes >= 95 % of its weight there,
    // so log E is within 5 % of the largest log contrast to the point's neighbours.
    const double centre = 0.05 * (nearest + 0.5);
    if (std::abs(x - centre) <= 0.05 / 8) {
      const Eigen::Index row = static_cast<Eigen::Index>(el);
      EXPECT_GE(w(row, nearest), 0.95) << "element " << el << " x " << x;
      double contrast = 0;
      for (int j : {nearest - 1, nearest + 1}) {
        if (j >= 0 && j < 8) {
          contrast = std::max(contrast, std::abs(std::log(values[static_cast<std::size_t>(j)] /
                                                          values[static_cast<std::size_t>(nearest)])));
        }
      }
      EXPECT_LE(std::abs(std::log(e(row) / values[static_cast<std::size_t>(nearest)])), 0.05 * contrast + 1e-12);
    }
  }
  // A narrow kernel reproduces the values almost exactly near the points.
  MaterialMapOptions narrow;
  narrow.kernel_width_m = 0.005;
  const Eigen::VectorXd sharp = MaterialMap(bar(), axis_points(8), narrow).element_values(values);
  for (std::size_t el = 0; el < centroids.size(); ++el) {
    const int nearest = std::clamp(static_cast<int>(centroids[el].x() / 0.05), 0, 7);
    if (std::abs(centroids[el].x() - 0.05 * (nearest + 0.5)) < 0.0125) {
      EXPECT_NEAR(sharp(static_cast<Eigen::Index>(el)) / values[static_cast<std::size_t>(nearest)], 1.0, 1e-6);
    }
  }
}

TEST(FemMaterialMap, TheFieldChangesSmoothlyAndMonotonicallyBetweenTwoPoints) {
  // Two points a quarter of the bar from each end: log E is a logistic function of x (the
  // Gaussian kernels' ratio), so it rises monotonically from one value to the other with no jump
  // between neighbouring elements larger than the slope allows.
  const TetMesh mesh = bar();
  const std::vector<Eigen::Vector3d> points = {{0.1, 0.025, 0.025}, {0.3, 0.025, 0.025}};
  const MaterialMap map(mesh, points);
  EXPECT_NEAR(map.kernel_width_m(), 0.2 / 3.0, 1e-12);
  const Eigen::VectorXd e = map.element_values({1e5, 1e6});
  const std::vector<Eigen::Vector3d> centroids = element_centroids(mesh);
  std::vector<std::pair<double, double>> profile;  // (x, log E)
  for (std::size_t el = 0; el < centroids.size(); ++el) {
    profile.emplace_back(centroids[el].x(), std::log(e(static_cast<Eigen::Index>(el))));
  }
  std::sort(profile.begin(), profile.end());
  // log E = log 1e5 + log 10 / (1 + exp(-(x - 0.2) d / sigma^2)), d = 0.2: largest slope at the
  // middle, log 10 d / (4 sigma^2).
  const double sigma = 0.2 / 3.0;
  const double steepest = std::log(10.0) * 0.2 / (4 * sigma * sigma);
  for (std::size_t i = 1; i < profile.size(); ++i) {
    const double dx = profile[i].first - profile[i - 1].first;
    const double dlog = profile[i].second - profile[i - 1].second;
    EXPECT_GE(dlog, -1e-12) << "x " << profile[i].first;
    EXPECT_LE(dlog, steepest * dx + 1e-12) << "x " << profile[i].first;
  }
  for (const auto& [x, log_e] : profile) {
    const double expected = std::log(1e5) + std::log(10.0) / (1 + std::exp(-(x - 0.2) * 0.2 / (sigma * sigma)));
    EXPECT_NEAR(log_e, expected, 1e-9) << "x " << x;
  }
}

TEST(FemMaterialMap, FarFromEveryPointTheNearestWins) {
  // Points far outside the mesh (the bar spans x = 0..0.4, so x = +100 is the nearer one): the
  // kernel must not underflow to 0/0.
  const MaterialMap map(bar(), {Eigen::Vector3d(-100, 0, 0), Eigen::Vector3d(100, 0, 0)},
                        MaterialMapOptions{0.01, 1.0 / 3.0});
  const Eigen::VectorXd e = map.element_values({2e5, 8e5});
  EXPECT_TRUE(e.allFinite());
  EXPECT_NEAR(e.minCoeff(), 8e5, 1e-6);
  EXPECT_NEAR(e.maxCoeff(), 8e5, 1e-6);
}

TEST(FemMaterialMap, PlacementIsDeterministicAndSpreadsAlongTheBar) {
  const TetMesh mesh = bar();
  const auto a = place_control_points(mesh, 4);
  const auto b = place_control_points(mesh, 4);
  ASSERT_EQ(a.size(), 4u);
  for (std::size_t i = 0; i < a.size(); ++i) EXPECT_EQ(a[i], b[i]);
  // Ordered along x (the longest axis), one per quarter of the bar, near the middle of each.
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_NEAR(a[i].x(), 0.1 * (static_cast<double>(i) + 0.5), 0.02) << i;
    EXPECT_NEAR(a[i].y(), 0.025, 0.01);
    EXPECT_NEAR(a[i].z(), 0.025, 0.01);
  }
  const auto one = place_control_points(mesh, 1);
  ASSERT_EQ(one.size(), 1u);
  EXPECT_NEAR(one[0].x(), 0.2, 1e-9);
}

TEST(FemMaterialMap, RefusesBadInput) {
  const TetMesh mesh = bar();
  EXPECT_THROW(MaterialMap(mesh, {}), std::invalid_argument);
  EXPECT_THROW(MaterialMap(mesh, {Eigen::Vector3d(0.1, 0, 0), Eigen::Vector3d(0.1, 0, 0)}), std::invalid_argument);
  EXPECT_THROW(MaterialMap(mesh, {Eigen::Vector3d(std::nan(""), 0, 0)}), std::invalid_argument);
  EXPECT_THROW(MaterialMap(TetMesh{}, axis_points(2)), std::invalid_argument);
  const MaterialMap map(mesh, axis_points(2));
  EXPECT_THROW(map.element_values({1e5}), std::invalid_argument);
  EXPECT_THROW(map.element_values({1e5, -1.0}), std::invalid_argument);
  EXPECT_THROW(place_control_points(mesh, 0), std::invalid_argument);
  EXPECT_THROW(place_control_points(mesh, 3001), std::invalid_argument);
}

}  // namespace
