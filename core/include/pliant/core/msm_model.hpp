// Meshless shape matching (MSM): the immutable model (rest shape, masses, roles, clusters).
//
// Frames and units: positions are in the caller's length unit (m or px) in one fixed frame;
// masses in kg (only ratios matter to MSM). Dim is 2 or 3; Scalar is float or double.
//
// Lifecycle (no heap, ever):
//   std::size_t bytes = msm_model_workspace_size(config);      // init time, O(N^2)
//   Arena arena(block, bytes);                                  // caller-owned memory
//   Status s = msm_model_init(arena, config, model);            // init time, O(N^2)
// The model is immutable afterwards and may be shared by any number of MsmState objects and
// estimators. The arrays in `config` are copied; the caller may free them after init.
//
// Clusters (Mueller et al. 2005, cluster shape matching): by default one cluster per
// particle holding every particle within radius_factor (1.5) x the median nearest-neighbour
// distance of the rest shape (a particle with no neighbour that close, but one within twice
// that, takes radius_factor x its own nearest-neighbour distance). Alternatives: the particle and its k nearest
// neighbours, or the paper's overlapping rectangular blocks (3 wide x 2 tall) on a particle grid.
#pragma once

#include <cstddef>
#include <cstdint>
#include <type_traits>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "pliant/core/arena.hpp"
#include "pliant/core/status.hpp"

namespace pliant {

enum class ClusterLayout : std::uint8_t {
  radius,      ///< one cluster per particle: all particles within radius_factor x median NN distance
  k_nearest,   ///< one cluster per particle: itself and its k nearest neighbours
  grid_blocks  ///< every block_cols x block_rows (x block_layers) window of a particle grid, stride 1
};

struct ClusterConfig {
  ClusterLayout layout = ClusterLayout::radius;
  double radius_factor = 1.5;  ///< radius layout; > 0
  int k = 8;                   ///< k_nearest layout; 1..64
  /// grid_blocks layout: particle id = (layer * grid_rows + row) * grid_cols + col, and
  /// grid_cols * grid_rows * grid_layers == particle_count. The paper uses 3 x 2 blocks.
  int grid_cols = 0, grid_rows = 0, grid_layers = 1;
  int block_cols = 3, block_rows = 2, block_layers = 1;
};

template <int Dim, typename Scalar>
struct MsmModelConfig {
  static_assert(Dim == 2 || Dim == 3, "MSM is defined in 2D and 3D");
  int particle_count = 0;                  ///< N >= 1
  const Scalar* rest_positions = nullptr;  ///< N * Dim, particle-major
  const Scalar* masses = nullptr;          ///< N, each finite > 0; nullptr = 1 for all
  const std::uint8_t* fixed = nullptr;     ///< N flags, 1 = pinned at rest; nullptr = none
  const int* drivable_ids = nullptr;       ///< particles that may be driven (the tool contact)
  int drivable_count = 0;
  /// The paper makes the manipulated particle heavier so it pulls cluster centroids toward the
  /// tool. 1 (default) uses masses as given; the factor multiplies drivable particles' masses.
  double driven_mass_factor = 1.0;
  ClusterConfig clusters;
};

/// Clusters per batch of the step's vectorised cluster pass (see MsmModel::cluster_lanes).
inline constexpr int kMsmClusterBatch = 8;
template <int Dim>
inline constexpr int kMsmClusterLaneFields = Dim + Dim* Dim + 1;

template <int Dim, typename Scalar>
struct MsmModel {
  using Vec = Eigen::Matrix<Scalar, Dim, 1>;
  using Mat = Eigen::Matrix<Scalar, Dim, Dim>;

  int particle_count = 0;
  int cluster_count = 0;
  int membership_count = 0;                 ///< total cluster members over all clusters
  Scalar spacing = 0;                       ///< median nearest-neighbour distance of the rest shape
  Vec* rest = nullptr;                      ///< [particle_count]
  Scalar* mass = nullptr;                   ///< [particle_count], drivable ones scaled
  std::uint8_t* fixed = nullptr;            ///< [particle_count]
  std::uint8_t* drivable = nullptr;         ///< [particle_count]
  Scalar* inverse_cluster_count = nullptr;  ///< [particle_count] 1/(clusters holding i), 0 if none
  std::int32_t* cluster_begin = nullptr;    ///< [cluster_count + 1] offsets into members
  std::int32_t* members = nullptr;          ///< [membership_count] particle ids
  Vec* member_rest_offset = nullptr;        ///< [membership_count] q0 = rest - cluster centroid
  Vec* cluster_rest_centroid = nullptr;     ///< [cluster_count]
  Scalar* cluster_inverse_mass = nullptr;   ///< [cluster_count]
  Mat* cluster_aqq_inverse = nullptr;       ///< [cluster_count] pseudo-inverse of sum m q0 q0^T
  /// Transpose of the cluster lists: particle i belongs to the clusters
  /// particle_clusters[particle_cluster_begin[i] .. particle_cluster_begin[i + 1]).
  std::int32_t* particle_cluster_begin = nullptr;  ///< [particle_count + 1]
  std::int32_t* particle_clusters = nullptr;       ///< [membership_count] cluster ids
  /// The same two lists as byte offsets into the step's per-particle moments and per-cluster
  /// goal maps (members[k] and particle_clusters[k] times sizeof(Eigen::Matrix<Scalar, Dim,
  /// Dim + 1>)), which spares the step's gathers an index multiplication per membership.
  std::int32_t* member_byte_offset = nullptr;            ///< [membership_count]
  std::int32_t* particle_cluster_byte_offset = nullptr;  ///< [membership_count]
  /// Per-cluster constants of the step in batches of kMsmClusterBatch clusters, lane-wise
  /// (structure of arrays) for its vectorised cluster pass: per batch b, field f, lane l at
  /// cluster_lanes[(b * kMsmClusterLaneFields<Dim> + f) * kMsmClusterBatch + l], fields the
  /// rest centroid relative to rest_origin (Dim), cluster_aqq_inverse column-major (Dim^2)
  /// and cluster_inverse_mass (1). Lanes past the last cluster repeat the batch's first.
  Scalar* cluster_lanes = nullptr;
  /// Mean rest position. The step works in coordinates relative to it (rest) and to the
  /// current mean position (deformed), which keeps float sums of x q^T precise.
  Vec rest_origin = Vec::Zero();

  bool initialized() const noexcept { return particle_count > 0 && rest != nullptr; }
};

/// Bytes of caller memory msm_model_init needs for `config` (0 when config is invalid).
/// Init time only: O(N^2) in the particle count.
template <int Dim, typename Scalar>
std::size_t msm_model_workspace_size(const MsmModelConfig<Dim, Scalar>& config) noexcept;

/// Builds the model in `arena`. Errors: invalid_argument (N < 1, bad cluster options, ids out
/// of range), non_finite_input, invalid_mass, duplicate_rest_positions, degenerate_cluster (a
/// cluster with a single member cannot define a rotation: a particle farther than twice the
/// cluster radius from every other), capacity_exceeded (arena too small).
/// On error the model is left uninitialized.
template <int Dim, typename Scalar>
[[nodiscard]] Status msm_model_init(Arena& arena, const MsmModelConfig<Dim, Scalar>& config,
                                    MsmModel<Dim, Scalar>& model) noexcept;

}  // namespace pliant
