#include "pliant/core/msm_model.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Eigenvalues>

namespace pliant {
namespace {

template <int Dim, typename Scalar>
double distance_squared(const Scalar* rest, int i, int j) noexcept {
  double sum = 0;
  for (int d = 0; d < Dim; ++d) {
    const double diff = static_cast<double>(rest[i * Dim + d]) - static_cast<double>(rest[j * Dim + d]);
    sum += diff * diff;
  }
  return sum;
}

template <int Dim, typename Scalar>
double nearest_distance_squared(const Scalar* rest, int count, int i) noexcept {
  double best = std::numeric_limits<double>::infinity();
  for (int j = 0; j < count; ++j) {
    if (j != i) best = std::min(best, distance_squared<Dim>(rest, i, j));
  }
  return best;
}

// Exact lower median of the nearest-neighbour distances (squared) without storing them: each
// round histograms the values still in range, keeps the bin holding the median rank and
// narrows the range to that bin's own min and max (binning is monotonic, so the bin is exactly
// the values in that range). O(N^2) per round; a few rounds; no heap, ~1 KiB of stack.
template <int Dim, typename Scalar>
double median_nearest_distance_squared(const Scalar* rest, int count) noexcept {
  if (count < 2) return 0;
  const int rank = (count - 1) / 2;
  double lo = std::numeric_limits<double>::infinity();
  double hi = -lo;
  for (int i = 0; i < count; ++i) {
    const double v = nearest_distance_squared<Dim>(rest, count, i);
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
  int below = 0;
  constexpr int kBins = 64;
  constexpr int kExact = 32;
  for (int round = 0; round < 64; ++round) {
    if (!(lo < hi)) return lo;
    int bin_count[kBins] = {};
    double bin_min[kBins];
    double bin_max[kBins];
    std::fill(bin_min, bin_min + kBins, std::numeric_limits<double>::infinity());
    std::fill(bin_max, bin_max + kBins, -std::numeric_limits<double>::infinity());
    double exact[kExact];
    int inside = 0;
    const double width = (hi - lo) / kBins;
    for (int i = 0; i < count; ++i) {
      const double v = nearest_distance_squared<Dim>(rest, count, i);
      if (v < lo || v > hi) continue;
      const int b = std::min(kBins - 1, static_cast<int>((v - lo) / width));
      ++bin_count[b];
      bin_min[b] = std::min(bin_min[b], v);
      bin_max[b] = std::max(bin_max[b], v);
      if (inside < kExact) exact[inside] = v;
      ++inside;
    }
    const int local_rank = rank - below;
    if (inside <= kExact) {
      std::sort(exact, exact + inside);
      return exact[local_rank];
    }
    int b = 0;
    for (; b < kBins - 1 && below + bin_count[b] <= rank; ++b) below += bin_count[b];
    lo = bin_min[b];
    hi = bin_max[b];
  }
  return lo;
}

// Calls visit(cluster, particle) for every membership, clusters in order, members ascending.
// Returns the number of clusters.
template <int Dim, typename Scalar, typename Visit>
int enumerate_clusters(const MsmModelConfig<Dim, Scalar>& config, double radius_squared, Visit&& visit) noexcept {
  const int n = config.particle_count;
  const ClusterConfig& cc = config.clusters;
  switch (cc.layout) {
    case ClusterLayout::radius:
      for (int c = 0; c < n; ++c) {
        // A particle with no neighbour inside the radius (a sparse spot of a sagged or
        // irregular rest shape) takes the radius factor times its own nearest-neighbour
        // distance, up to twice the radius; farther out it stays alone and is rejected.
        double own_radius_squared = radius_squared;
        const double nearest = nearest_distance_squared<Dim>(config.rest_positions, n, c);
        if (n > 1 && nearest > radius_squared && nearest <= 4.0 * radius_squared) {
          own_radius_squared = cc.radius_factor * cc.radius_factor * nearest * (1.0 + 1e-12);
        }
        for (int j = 0; j < n; ++j) {
          if (distance_squared<Dim>(config.rest_positions, c, j) <= own_radius_squared) visit(c, j);
        }
      }
      return n;
    case ClusterLayout::k_nearest:
      for (int c = 0; c < n; ++c) {
        constexpr int kMaxK = 64;
        int best_id[kMaxK + 1];
        double best_d[kMaxK + 1];
        int kept = 0;
        const int k = std::min(cc.k, n - 1);
        for (int j = 0; j < n; ++j) {
          if (j == c) continue;
          const double d = distance_squared<Dim>(config.rest_positions, c, j);
          if (kept == k && !(d < best_d[kept - 1])) continue;
          int slot = kept < k ? kept++ : kept - 1;
          while (slot > 0 && best_d[slot - 1] > d) {
            best_d[slot] = best_d[slot - 1];
            best_id[slot] = best_id[slot - 1];
            --slot;
          }
          best_d[slot] = d;
          best_id[slot] = j;
        }
        best_id[kept] = c;
        std::sort(best_id, best_id + kept + 1);
        for (int m = 0; m <= kept; ++m) visit(c, best_id[m]);
      }
      return n;
    case ClusterLayout::grid_blocks: {
      int cluster = 0;
      for (int l0 = 0; l0 + cc.block_layers <= cc.grid_layers; ++l0) {
        for (int r0 = 0; r0 + cc.block_rows <= cc.grid_rows; ++r0) {
          for (int c0 = 0; c0 + cc.block_cols <= cc.grid_cols; ++c0) {
            for (int l = l0; l < l0 + cc.block_layers; ++l) {
              for (int r = r0; r < r0 + cc.block_rows; ++r) {
                for (int c = c0; c < c0 + cc.block_cols; ++c) {
                  visit(cluster, (l * cc.grid_rows + r) * cc.grid_cols + c);
                }
              }
            }
            ++cluster;
          }
        }
      }
      return cluster;
    }
  }
  return 0;
}

template <int Dim, typename Scalar>
Status validate(const MsmModelConfig<Dim, Scalar>& config) noexcept {
  const int n = config.particle_count;
  if (n < 1 || config.rest_positions == nullptr) return Status::invalid_argument;
  for (int i = 0; i < n * Dim; ++i) {
    if (!std::isfinite(static_cast<double>(config.rest_positions[i]))) return Status::non_finite_input;
  }
  if (config.masses != nullptr) {
    for (int i = 0; i < n; ++i) {
      const double m = static_cast<double>(config.masses[i]);
      if (!std::isfinite(m) || !(m > 0)) return Status::invalid_mass;
    }
  }
  if (!std::isfinite(config.driven_mass_factor) || !(config.driven_mass_factor > 0)) return Status::invalid_mass;
  if (config.drivable_count < 0 || (config.drivable_count > 0 && config.drivable_ids == nullptr)) {
    return Status::invalid_argument;
  }
  for (int i = 0; i < config.drivable_count; ++i) {
    if (config.drivable_ids[i] < 0 || config.drivable_ids[i] >= n) return Status::invalid_argument;
  }
  const ClusterConfig& cc = config.clusters;
  switch (cc.layout) {
    case ClusterLayout::radius:
      if (!std::isfinite(cc.radius_factor) || !(cc.radius_factor > 0)) return Status::invalid_argument;
      break;
    case ClusterLayout::k_nearest:
      if (cc.k < 1 || cc.k > 64) return Status::invalid_argument;
      break;
    case ClusterLayout::grid_blocks: {
      const bool sizes_ok = cc.grid_cols > 0 && cc.grid_rows > 0 && cc.grid_layers > 0 && cc.block_cols > 0 &&
                            cc.block_rows > 0 && cc.block_layers > 0 && cc.block_cols <= cc.grid_cols &&
                            cc.block_rows <= cc.grid_rows && cc.block_layers <= cc.grid_layers;
      if (!sizes_ok || static_cast<long long>(cc.grid_cols) * cc.grid_rows * cc.grid_layers != n) {
        return Status::invalid_argument;
      }
      if (Dim == 2 && cc.grid_layers != 1) return Status::invalid_argument;
      break;
    }
  }
  return Status::ok;
}

template <int Dim, typename Scalar>
Status build(Arena& arena, const MsmModelConfig<Dim, Scalar>& config, MsmModel<Dim, Scalar>& model) noexcept {
  using Vec = typename MsmModel<Dim, Scalar>::Vec;
  using Mat = typename MsmModel<Dim, Scalar>::Mat;
  using MatD = Eigen::Matrix<double, Dim, Dim>;
  using VecD = Eigen::Matrix<double, Dim, 1>;
  model = MsmModel<Dim, Scalar>{};
  const Status valid = validate(config);
  if (valid != Status::ok) return valid;
  const int n = config.particle_count;

  // Duplicates: a zero nearest-neighbour distance relative to the object's extent.
  double extent_squared = 0;
  for (int i = 1; i < n; ++i)
    extent_squared = std::max(extent_squared, distance_squared<Dim>(config.rest_positions, 0, i));
  for (int i = 0; i < n && n > 1; ++i) {
    if (nearest_distance_squared<Dim>(config.rest_positions, n, i) <= 1e-24 * extent_squared) {
      return Status::duplicate_rest_positions;
    }
  }
  const double median_squared = median_nearest_distance_squared<Dim>(config.rest_positions, n);
  const double radius = config.clusters.radius_factor * std::sqrt(median_squared);
  const double radius_squared = radius * radius * (1.0 + 1e-12);

  int memberships = 0;
  const int clusters = enumerate_clusters(config, radius_squared, [&](int, int) { ++memberships; });
  if (clusters < 1) return Status::degenerate_cluster;

  // The step's gathers address per-particle and per-cluster blocks by int32 byte offsets.
  constexpr auto kMomentBytes = static_cast<long long>(sizeof(Eigen::Matrix<Scalar, Dim, Dim + 1>));
  if (static_cast<long long>(std::max(n, clusters)) * kMomentBytes > 0x7fffffffLL) return Status::invalid_argument;

  MsmModel<Dim, Scalar> m;
  m.particle_count = n;
  m.cluster_count = clusters;
  m.membership_count = memberships;
  m.spacing = static_cast<Scalar>(std::sqrt(median_squared));
  m.rest = arena.carve<Vec>(static_cast<std::size_t>(n));
  m.mass = arena.carve<Scalar>(static_cast<std::size_t>(n));
  m.fixed = arena.carve<std::uint8_t>(static_cast<std::size_t>(n));
  m.drivable = arena.carve<std::uint8_t>(static_cast<std::size_t>(n));
  m.inverse_cluster_count = arena.carve<Scalar>(static_cast<std::size_t>(n));
  m.cluster_begin = arena.carve<std::int32_t>(static_cast<std::size_t>(clusters) + 1);
  m.members = arena.carve<std::int32_t>(static_cast<std::size_t>(memberships));
  m.member_rest_offset = arena.carve<Vec>(static_cast<std::size_t>(memberships));
  m.cluster_rest_centroid = arena.carve<Vec>(static_cast<std::size_t>(clusters));
  m.cluster_inverse_mass = arena.carve<Scalar>(static_cast<std::size_t>(clusters));
  m.cluster_aqq_inverse = arena.carve<Mat>(static_cast<std::size_t>(clusters));
  m.particle_cluster_begin = arena.carve<std::int32_t>(static_cast<std::size_t>(n) + 1);
  m.particle_clusters = arena.carve<std::int32_t>(static_cast<std::size_t>(memberships));
  m.member_byte_offset = arena.carve<std::int32_t>(static_cast<std::size_t>(memberships));
  m.particle_cluster_byte_offset = arena.carve<std::int32_t>(static_cast<std::size_t>(memberships));
  const int batches = (clusters + kMsmClusterBatch - 1) / kMsmClusterBatch;
  m.cluster_lanes =
      arena.carve<Scalar>(static_cast<std::size_t>(batches) * kMsmClusterLaneFields<Dim> * kMsmClusterBatch);
  if (arena.exhausted()) return Status::capacity_exceeded;

  for (int i = 0; i < n; ++i) {
    for (int d = 0; d < Dim; ++d) m.rest[i](d) = config.rest_positions[i * Dim + d];
    m.mass[i] = config.masses != nullptr ? config.masses[i] : Scalar(1);
    m.fixed[i] = config.fixed != nullptr && config.fixed[i] != 0 ? 1 : 0;
    m.drivable[i] = 0;
    m.inverse_cluster_count[i] = 0;
  }
  for (int k = 0; k < config.drivable_count; ++k) {
    const int id = config.drivable_ids[k];
    if (m.drivable[id] == 0)
      m.mass[id] = static_cast<Scalar>(static_cast<double>(m.mass[id]) * config.driven_mass_factor);
    m.drivable[id] = 1;
  }

  int filled = 0;
  int current = -1;
  enumerate_clusters(config, radius_squared, [&](int c, int j) {
    while (current < c) m.cluster_begin[++current] = filled;
    m.members[filled++] = j;
    m.inverse_cluster_count[j] += Scalar(1);
  });
  while (current < clusters) m.cluster_begin[++current] = filled;

  // Transposed lists (particle -> clusters), by counting then filling.
  m.particle_cluster_begin[0] = 0;
  for (int i = 0; i < n; ++i) {
    m.particle_cluster_begin[i + 1] =
        m.particle_cluster_begin[i] + static_cast<std::int32_t>(m.inverse_cluster_count[i]);
  }
  for (int c = 0; c < clusters; ++c) {
    for (int k = m.cluster_begin[c]; k < m.cluster_begin[c + 1]; ++k) {
      const int j = m.members[k];
      // inverse_cluster_count[j] still holds the count; use it as a countdown cursor.
      m.inverse_cluster_count[j] -= Scalar(1);
      m.particle_clusters[m.particle_cluster_begin[j] + static_cast<std::int32_t>(m.inverse_cluster_count[j])] = c;
    }
  }
  for (int k = 0; k < memberships; ++k) {
    m.member_byte_offset[k] = static_cast<std::int32_t>(m.members[k] * kMomentBytes);
    m.particle_cluster_byte_offset[k] = static_cast<std::int32_t>(m.particle_clusters[k] * kMomentBytes);
  }
  VecD origin = VecD::Zero();
  for (int i = 0; i < n; ++i) {
    origin += m.rest[i].template cast<double>();
    const int held_count = m.particle_cluster_begin[i + 1] - m.particle_cluster_begin[i];
    m.inverse_cluster_count[i] = static_cast<Scalar>(held_count);
  }
  m.rest_origin = (origin / static_cast<double>(n)).template cast<Scalar>();

  for (int i = 0; i < n; ++i) {
    const Scalar held = m.inverse_cluster_count[i];
    m.inverse_cluster_count[i] = held > 0 ? Scalar(1) / held : Scalar(0);
  }

  for (int c = 0; c < clusters; ++c) {
    const int begin = m.cluster_begin[c];
    const int end = m.cluster_begin[c + 1];
    if (end - begin < 2) return Status::degenerate_cluster;
    double mass_sum = 0;
    VecD centroid = VecD::Zero();
    for (int k = begin; k < end; ++k) {
      const int j = m.members[k];
      const double mj = static_cast<double>(m.mass[j]);
      mass_sum += mj;
      centroid += mj * m.rest[j].template cast<double>();
    }
    centroid /= mass_sum;
    MatD aqq = MatD::Zero();
    for (int k = begin; k < end; ++k) {
      const int j = m.members[k];
      const VecD q = m.rest[j].template cast<double>() - centroid;
      aqq += static_cast<double>(m.mass[j]) * q * q.transpose();
      m.member_rest_offset[k] = q.template cast<Scalar>();
    }
    // Pseudo-inverse: collinear (2D) or flat (3D) clusters have a rank-deficient A_qq; the
    // affine fit then acts only inside the cluster's span, which is all its goals need. A
    // direction whose extent is under ~3 % of the cluster's (variance ratio 1e-3) is treated as
    // absent: in a nearly flat cluster it holds only measurement noise, which inverting would
    // amplify into a spurious stretch.
    constexpr double kFlatVarianceRatio = 1e-3;
    Eigen::SelfAdjointEigenSolver<MatD> eigen;
    eigen.computeDirect(aqq);
    const VecD lambda = eigen.eigenvalues();
    const double threshold = lambda.cwiseAbs().maxCoeff() * kFlatVarianceRatio;
    VecD inverse_lambda;
    for (int d = 0; d < Dim; ++d) inverse_lambda(d) = lambda(d) > threshold ? 1.0 / lambda(d) : 0.0;
    const MatD aqq_inverse = eigen.eigenvectors() * inverse_lambda.asDiagonal() * eigen.eigenvectors().transpose();
    m.cluster_aqq_inverse[c] = aqq_inverse.template cast<Scalar>();
    m.cluster_rest_centroid[c] = centroid.template cast<Scalar>();
    m.cluster_inverse_mass[c] = static_cast<Scalar>(1.0 / mass_sum);
  }
  for (int b = 0; b < batches; ++b) {
    Scalar* block = m.cluster_lanes + static_cast<std::ptrdiff_t>(b) * kMsmClusterLaneFields<Dim> * kMsmClusterBatch;
    for (int lane = 0; lane < kMsmClusterBatch; ++lane) {
      const int c = b * kMsmClusterBatch + lane < clusters ? b * kMsmClusterBatch + lane : b * kMsmClusterBatch;
      int field = 0;
      for (int d = 0; d < Dim; ++d)
        block[field++ * kMsmClusterBatch + lane] = m.cluster_rest_centroid[c](d) - m.rest_origin(d);
      for (int e = 0; e < Dim * Dim; ++e) block[field++ * kMsmClusterBatch + lane] = m.cluster_aqq_inverse[c].data()[e];
      block[field * kMsmClusterBatch + lane] = m.cluster_inverse_mass[c];
    }
  }
  model = m;
  return Status::ok;
}

}  // namespace

template <int Dim, typename Scalar>
std::size_t msm_model_workspace_size(const MsmModelConfig<Dim, Scalar>& config) noexcept {
  Arena measure;
  MsmModel<Dim, Scalar> scratch;
  const Status status = build(measure, config, scratch);
  if (status != Status::capacity_exceeded && status != Status::ok) return 0;
  return measure.required_bytes();
}

template <int Dim, typename Scalar>
Status msm_model_init(Arena& arena, const MsmModelConfig<Dim, Scalar>& config, MsmModel<Dim, Scalar>& model) noexcept {
  if (arena.measuring()) return Status::capacity_exceeded;
  return build(arena, config, model);
}

#define PLIANT_INSTANTIATE_MSM_MODEL(DIM, SCALAR)                                                          \
  template std::size_t msm_model_workspace_size<DIM, SCALAR>(const MsmModelConfig<DIM, SCALAR>&) noexcept; \
  template Status msm_model_init<DIM, SCALAR>(Arena&, const MsmModelConfig<DIM, SCALAR>&,                  \
                                              MsmModel<DIM, SCALAR>&) noexcept;
PLIANT_INSTANTIATE_MSM_MODEL(2, float)
PLIANT_INSTANTIATE_MSM_MODEL(2, double)
PLIANT_INSTANTIATE_MSM_MODEL(3, float)
PLIANT_INSTANTIATE_MSM_MODEL(3, double)
#undef PLIANT_INSTANTIATE_MSM_MODEL

}  // namespace pliant
