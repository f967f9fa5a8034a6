// Material maps: a few control points, each carrying a Young's modulus, interpolated smoothly
// to one modulus per tetrahedron (Wang et al., "Deformation capture and modeling of soft
// objects": heterogeneous objects described by a handful of material control points, so a
// trajectory fit estimates k values instead of one per element).
//
// Interpolation. Element e with rest centroid c_e gets
//     log E_e = sum_i w_ei log v_i,   w_ei = g_i(c_e) / sum_j g_j(c_e),
//     g_i(c) = exp(-|c - p_i|^2 / (2 sigma^2)),
// a normalised Gaussian (Shepard-type) kernel on the control positions p_i with values v_i.
// Consequences, all by construction:
//  * the weights of every element are non-negative and sum to one (partition of unity), so
//    E_e lies in [min_i v_i, max_i v_i], and one control point gives a uniform field;
//  * interpolating log E keeps ratios symmetric (halfway between 1e4 and 1e6 is 1e5) and keeps
//    values positive, matching the log-scale parameters of the estimators;
//  * far from every control point the nearest one dominates (the kernel is evaluated relative
//    to the nearest point, so it never underflows to 0/0).
// Kernel width sigma (m): MaterialMapOptions::kernel_width_m, or by default width_factor (1/3)
// times the mean over the control points of the distance to their nearest neighbour. With
// sigma = d/3 for neighbours d apart, a control point keeps about 98 % of the weight at its own
// position, and the value changes from one point's to the next over about half the spacing.
//
// Frames and units: control positions in the mesh (recording) frame, m; values in Pa. The
// weights depend on the rest mesh only, so they are computed once (O(m k) time and memory for m
// elements and k control points) and every evaluation is O(m k).
// Host code: allocates, throws std::invalid_argument on bad input.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "pliant/host/fem/fem_model.hpp"
#include "pliant/host/recording.hpp"

namespace pliant::host::fem {

struct MaterialMapOptions {
  /// Gaussian width sigma (m, > 0), or 0 for the automatic rule below.
  double kernel_width_m = 0;
  /// Automatic rule: sigma = width_factor * mean nearest-neighbour distance of the control points
  /// (> 0). With a single control point the width does not matter (uniform field).
  double width_factor = 1.0 / 3.0;
};

/// Rest centroid (m) of every tetrahedron of `mesh`.
std::vector<Eigen::Vector3d> element_centroids(const TetMesh& mesh);

/// Interpolation weights from control points to the elements of one mesh.
class MaterialMap {
 public:
  /// control_points_m: k >= 1 distinct, finite positions (m). Throws std::invalid_argument on an
  /// empty or non-finite set, two coincident points, an empty mesh, or bad options.
  MaterialMap(const TetMesh& mesh, std::vector<Eigen::Vector3d> control_points_m,
              const MaterialMapOptions& options = {});

  int control_point_count() const { return static_cast<int>(points_.size()); }
  int element_count() const { return static_cast<int>(weights_.rows()); }
  const std::vector<Eigen::Vector3d>& control_points_m() const { return points_; }
  /// The sigma in use (m); for one control point the diagonal of the mesh's bounding box.
  double kernel_width_m() const { return width_m_; }
  /// m x k weights: row e holds w_ei, non-negative, summing to 1.
  const Eigen::MatrixXd& weights() const { return weights_; }

  /// Per-element modulus (Pa, m entries) from k control values (Pa, each > 0 and finite; throws
  /// std::invalid_argument otherwise). O(m k).
  Eigen::VectorXd element_values(const std::vector<double>& control_values_pa) const;

  /// Index of the control point with the largest weight for each element (its "region").
  std::vector<int> dominant_control_point() const;

 private:
  std::vector<Eigen::Vector3d> points_;
  double width_m_ = 0;
  Eigen::MatrixXd weights_;
};

/// k control positions spread over the mesh, deterministically: farthest-point sampling on the
/// element centroids (starting from the centroid farthest from the mesh's volume-weighted
/// centre) seeds a volume-weighted k-means (Lloyd) on the centroids, 50 iterations at most; the
/// result is the k cluster centres, ordered along the mesh's longest bounding-box axis (ties
/// broken by the other axes). Throws std::invalid_argument unless 1 <= k <= element count.
std::vector<Eigen::Vector3d> place_control_points(const TetMesh& mesh, int k);

}  // namespace pliant::host::fem
