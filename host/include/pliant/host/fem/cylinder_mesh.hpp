// Structured tetrahedral mesh of a solid circular cylinder, for the FEM side (compression
// specimens, recording format v1 mesh.vtk). Host code only: allocates and throws.
//
// Layout. The axis is z, the bottom face lies at z = 0 and the top face at z = height_m; lengths
// are metres. The cross-section is an O-grid: a square core of (c/4) x (c/4) cells, its edges
// bulged halfway toward a circle, surrounded by `radial_divisions` rings of cells that reach the
// lateral surface, where c = `circumferential_divisions` nodes sit evenly on the circle (corners
// of the core at 45, 135, 225 and 315 degrees). Every quadrilateral cell is cut along its shorter
// diagonal into two triangles; the triangulated section is stacked `axial_layers` times and each
// triangular prism is split into three tetrahedra. The prism split takes the diagonal of every
// side face from the bottom of its lower-numbered section node to the top of the other, a rule
// that depends only on the face, so neighbouring prisms always agree: the mesh is conforming
// (every interior triangle is shared by exactly two tetrahedra).
//
// Numbering. Points are level-major: point = level * S + s, with level 0 (z = 0) .. axial_layers
// (z = height_m) and S = (c/4 + 1)^2 + radial_divisions * c section nodes. Section node
// (c/8) * (c/4 + 1) + c/8 is the axis (x = y = 0 exactly) at every level. So points 0..S-1 are
// the bottom face and the last S points the top face, with z exactly 0 and exactly height_m.
//
// Geometry. Lateral-surface nodes lie exactly on the circle, so the section is the inscribed
// c-gon: the mesh volume is pi r^2 h * (c / (2 pi)) sin(2 pi / c), 1.1 % short at c = 24, 0.6 %
// at c = 32, converging from below as c grows. Every tetrahedron has positive volume (its four
// indices are ordered so that (p1-p0) x (p2-p0) . (p3-p0) > 0).
//
// Size: S * (axial_layers + 1) points, 3 * 2 * (c^2/16 + radial_divisions * c) * axial_layers
// tetrahedra; e.g. (2, 24, 5) gives 582 points and 2520 tetrahedra, (2, 16, 6) 399 points and
// 1728 tetrahedra. Work and memory are linear in the tetrahedron count.
#pragma once

#include "pliant/host/recording.hpp"

namespace pliant::host {

/// Division counts of cylinder_tet_mesh, as the command line takes them ("r,c,z").
struct CylinderMeshDivisions {
  int radial = 2;            ///< cell rings between the core and the lateral surface, >= 1
  int circumferential = 24;  ///< nodes around the circle, a multiple of 8, >= 8
  int axial = 5;             ///< layers of prisms along z, >= 1
};

/// Upper bound on the tetrahedra cylinder_tet_mesh makes (larger requests are refused).
inline constexpr long long kMaxCylinderTets = 5'000'000;

/// The mesh described above; `youngs_modulus` is left empty. Throws std::invalid_argument when a
/// dimension is not finite and positive, a division count is out of range (see
/// CylinderMeshDivisions) or the mesh would exceed kMaxCylinderTets.
TetMesh cylinder_tet_mesh(double diameter_m, double height_m, int radial_divisions, int circumferential_divisions,
                          int axial_layers);

inline TetMesh cylinder_tet_mesh(double diameter_m, double height_m, const CylinderMeshDivisions& divisions) {
  return cylinder_tet_mesh(diameter_m, height_m, divisions.radial, divisions.circumferential, divisions.axial);
}

/// Signed volume of tetrahedron `tet` of `mesh` (m^3 for a mesh in metres): positive when its
/// points are ordered as above. No bounds checks beyond those of std::vector::at.
double tet_signed_volume(const TetMesh& mesh, int tet);

}  // namespace pliant::host
