#include "pliant/host/fem/material_map.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>

#include <Eigen/Dense>

namespace pliant::host::fem {
namespace {

std::size_t uz(int i) { return static_cast<std::size_t>(i); }

Eigen::Vector3d point(const TetMesh& mesh, int id) {
  return {mesh.points[3 * uz(id)], mesh.points[3 * uz(id) + 1], mesh.points[3 * uz(id) + 2]};
}

void check_mesh(const TetMesh& mesh) {
  if (mesh.tet_count() < 1 || mesh.points.size() % 3 != 0 || mesh.tetrahedra.size() % 4 != 0) {
    throw std::invalid_argument("material map: empty or malformed mesh");
  }
  for (int id : mesh.tetrahedra) {
    if (id < 0 || id >= mesh.point_count()) throw std::invalid_argument("material map: tetrahedron index out of range");
  }
}

std::vector<double> element_volumes(const TetMesh& mesh) {
  std::vector<double> volume(uz(mesh.tet_count()));
  for (int e = 0; e < mesh.tet_count(); ++e) {
    const Eigen::Vector3d x0 = point(mesh, mesh.tetrahedra[4 * uz(e)]);
    Eigen::Matrix3d d;
    for (int a = 1; a < 4; ++a) d.col(a - 1) = point(mesh, mesh.tetrahedra[4 * uz(e) + uz(a)]) - x0;
    volume[uz(e)] = std::abs(d.determinant()) / 6.0;
  }
  return volume;
}

}  // namespace

std::vector<Eigen::Vector3d> element_centroids(const TetMesh& mesh) {
  check_mesh(mesh);
  std::vector<Eigen::Vector3d> centroids(uz(mesh.tet_count()));
  for (int e = 0; e < mesh.tet_count(); ++e) {
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    for (int a = 0; a < 4; ++a) c += point(mesh, mesh.tetrahedra[4 * uz(e) + uz(a)]);
    centroids[uz(e)] = 0.25 * c;
  }
  return centroids;
}

MaterialMap::MaterialMap(const TetMesh& mesh, std::vector<Eigen::Vector3d> control_points_m,
                         const MaterialMapOptions& options)
    : points_(std::move(control_points_m)) {
  if (points_.empty()) throw std::invalid_argument("material map: no control points");
  for (const Eigen::Vector3d& p : points_) {
    if (!p.allFinite()) throw std::invalid_argument("material map: non-finite control point");
  }
  if (!(options.kernel_width_m >= 0) || !std::isfinite(options.kernel_width_m) || !(options.width_factor > 0) ||
      !std::isfinite(options.width_factor)) {
    throw std::invalid_argument("material map: kernel width must be >= 0 and width factor > 0");
  }
  const std::vector<Eigen::Vector3d> centroids = element_centroids(mesh);
  const int k = control_point_count();
  const int m = static_cast<int>(centroids.size());

  // Nearest-neighbour spacing of the control points (and coincidence check).
  double spacing_sum = 0;
  for (int i = 0; i < k; ++i) {
    double nearest = std::numeric_limits<double>::infinity();
    for (int j = 0; j < k; ++j) {
      if (j != i) nearest = std::min(nearest, (points_[uz(i)] - points_[uz(j)]).norm());
    }
    if (k > 1 && !(nearest > 0)) throw std::invalid_argument("material map: two control points coincide");
    if (k > 1) spacing_sum += nearest;
  }
  if (options.kernel_width_m > 0) {
    width_m_ = options.kernel_width_m;
  } else if (k > 1) {
    width_m_ = options.width_factor * spacing_sum / k;
  } else {
    Eigen::Vector3d lo = centroids[0], hi = centroids[0];
    for (const Eigen::Vector3d& c : centroids) {
      lo = lo.cwiseMin(c);
      hi = hi.cwiseMax(c);
    }
    width_m_ = std::max((hi - lo).norm(), 1e-12);
  }

  // Kernel relative to the nearest control point: exponents <= 0 with one exactly 0, so the
  // normaliser is >= 1 and nothing underflows to 0/0 far from every point.
  weights_.resize(m, k);
  const double inv_two_sigma2 = 1.0 / (2.0 * width_m_ * width_m_);
  std::vector<double> d2(uz(k));
  for (int e = 0; e < m; ++e) {
    double nearest = std::numeric_limits<double>::infinity();
    for (int i = 0; i < k; ++i) {
      d2[uz(i)] = (centroids[uz(e)] - points_[uz(i)]).squaredNorm();
      nearest = std::min(nearest, d2[uz(i)]);
    }
    double sum = 0;
    for (int i = 0; i < k; ++i) {
      const double g = std::exp(-(d2[uz(i)] - nearest) * inv_two_sigma2);
      weights_(e, i) = g;
      sum += g;
    }
    weights_.row(e) /= sum;
  }
}

Eigen::VectorXd MaterialMap::element_values(const std::vector<double>& control_values_pa) const {
  if (static_cast<int>(control_values_pa.size()) != control_point_count()) {
    throw std::invalid_argument("material map: one value per control point expected");
  }
  Eigen::VectorXd log_values(control_point_count());
  for (int i = 0; i < control_point_count(); ++i) {
    const double v = control_values_pa[uz(i)];
    if (!(v > 0) || !std::isfinite(v)) throw std::invalid_argument("material map: values must be positive and finite");
    log_values(i) = std::log(v);
  }
  Eigen::VectorXd values = weights_ * log_values;
  // exp of a convex combination of logs: clamp the rounding so the bounds hold exactly.
  const double lo = *std::min_element(control_values_pa.begin(), control_values_pa.end());
  const double hi = *std::max_element(control_values_pa.begin(), control_values_pa.end());
  for (Eigen::Index e = 0; e < values.size(); ++e) values(e) = std::clamp(std::exp(values(e)), lo, hi);
  return values;
}

std::vector<int> MaterialMap::dominant_control_point() const {
  std::vector<int> dominant(uz(element_count()));
  for (int e = 0; e < element_count(); ++e) {
    Eigen::Index best = 0;
    weights_.row(e).maxCoeff(&best);
    dominant[uz(e)] = static_cast<int>(best);
  }
  return dominant;
}

std::vector<Eigen::Vector3d> place_control_points(const TetMesh& mesh, int k) {
  const std::vector<Eigen::Vector3d> centroids = element_centroids(mesh);
  const int m = static_cast<int>(centroids.size());
  if (k < 1 || k > m) throw std::invalid_argument("place_control_points: need 1 <= k <= element count");
  const std::vector<double> volume = element_volumes(mesh);

  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  double total = 0;
  for (int e = 0; e < m; ++e) {
    centre += volume[uz(e)] * centroids[uz(e)];
    total += volume[uz(e)];
  }
  centre /= total;

  // Farthest-point seeds: first the centroid farthest from the centre, then repeatedly the one
  // farthest from every seed so far (lowest index on ties: deterministic).
  std::vector<Eigen::Vector3d> seeds;
  std::vector<double> distance(uz(m), std::numeric_limits<double>::infinity());
  int next = 0;
  for (int e = 1; e < m; ++e) {
    if ((centroids[uz(e)] - centre).squaredNorm() > (centroids[uz(next)] - centre).squaredNorm()) next = e;
  }
  while (static_cast<int>(seeds.size()) < k) {
    seeds.push_back(centroids[uz(next)]);
    int farthest = 0;
    for (int e = 0; e < m; ++e) {
      distance[uz(e)] = std::min(distance[uz(e)], (centroids[uz(e)] - seeds.back()).squaredNorm());
      if (distance[uz(e)] > distance[uz(farthest)]) farthest = e;
    }
    next = farthest;
  }

  // Volume-weighted Lloyd iterations.
  std::vector<int> label(uz(m), -1);
  for (int iteration = 0; iteration < 50; ++iteration) {
    bool changed = false;
    for (int e = 0; e < m; ++e) {
      int best = 0;
      for (int i = 1; i < k; ++i) {
        if ((centroids[uz(e)] - seeds[uz(i)]).squaredNorm() < (centroids[uz(e)] - seeds[uz(best)]).squaredNorm())
          best = i;
      }
      if (label[uz(e)] != best) changed = true;
      label[uz(e)] = best;
    }
    if (!changed) break;
    std::vector<Eigen::Vector3d> sum(uz(k), Eigen::Vector3d::Zero());
    std::vector<double> weight(uz(k), 0.0);
    for (int e = 0; e < m; ++e) {
      sum[uz(label[uz(e)])] += volume[uz(e)] * centroids[uz(e)];
      weight[uz(label[uz(e)])] += volume[uz(e)];
    }
    for (int i = 0; i < k; ++i) {
      if (weight[uz(i)] > 0) seeds[uz(i)] = sum[uz(i)] / weight[uz(i)];  // an empty cluster keeps its seed
    }
  }

  // Order along the longest axis of the bounding box, then the others.
  Eigen::Vector3d lo = centroids[0], hi = centroids[0];
  for (const Eigen::Vector3d& c : centroids) {
    lo = lo.cwiseMin(c);
    hi = hi.cwiseMax(c);
  }
  const Eigen::Vector3d extent = hi - lo;
  std::array<int, 3> axes = {0, 1, 2};
  std::stable_sort(axes.begin(), axes.end(), [&](int a, int b) { return extent(a) > extent(b); });
  std::stable_sort(seeds.begin(), seeds.end(), [&](const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
    for (int axis : axes) {
      if (a(axis) != b(axis)) return a(axis) < b(axis);
    }
    return false;
  });
  return seeds;
}

}  // namespace pliant::host::fem
