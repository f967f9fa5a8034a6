// Structured tetrahedral meshes and uniform refinement, for FEM convergence studies, tests and
// benchmarks (not for fitting recordings: use the mesh a recording gives, see PHYSICS.md).
//
// Lengths in m. Every tetrahedron produced is positively oriented
// (det(X1 - X0, X2 - X0, X3 - X0) > 0). Host code: allocates, throws std::invalid_argument.
#pragma once

#include <array>
#include <vector>

#include <Eigen/Core>

#include "pliant/host/recording.hpp"

namespace pliant::host::fem {

enum class BoxSplit {
  /// Every cell split into the 6 tetrahedra around its (0,0,0)-(1,1,1) diagonal, all cells alike.
  /// Anisotropic: a cantilever bends slightly sideways.
  kuhn,
  /// The same split mirrored in x, y and z in alternate cells (checkerboard), still conforming:
  /// the mesh has the box's mirror symmetries, so no sideways bending.
  mirrored_kuhn,
};

/// Box [origin, origin + size] with cells[0] x cells[1] x cells[2] cells of 6 tetrahedra each.
/// Points are numbered x fastest: id = (k * (cells[1] + 1) + j) * (cells[0] + 1) + i. No Young's
/// modulus values (youngs_modulus empty). Sizes must be positive and cells >= 1.
TetMesh make_box_tet_mesh(const Eigen::Vector3d& size_m, const std::array<int, 3>& cells,
                          BoxSplit split = BoxSplit::mirrored_kuhn,
                          const Eigen::Vector3d& origin_m = Eigen::Vector3d::Zero());

/// Uniform refinement: every tetrahedron split in 8 through its edge midpoints (4 corner
/// tetrahedra and the inner octahedron cut along its shortest diagonal). Original points keep
/// their indices; midpoints follow. Per-tetrahedron Young's moduli are inherited. Element size
/// halves; element count x8; point count roughly x(1 + 7/8 * edges/points).
TetMesh refine_tet_mesh(const TetMesh& mesh);

/// Indices of the points whose coordinate `axis` (0, 1, 2) is within tolerance_m of value_m.
std::vector<int> points_on_plane(const TetMesh& mesh, int axis, double value_m, double tolerance_m);

}  // namespace pliant::host::fem
