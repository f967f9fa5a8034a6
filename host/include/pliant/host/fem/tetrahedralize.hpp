// Tetrahedralization of a closed triangle surface with TetGen 1.5 (Debian libtet1.5-dev), as a
// constrained Delaunay mesh of the enclosed volume, optionally refined for quality and size.
//
// Host code only: allocates and throws MeshError (mesh_io.hpp). POSIX only.
//
// TetGen runs in a child process (fork), for three reasons: TetGen 1.5.0 crashes while cleaning
// up after it detects bad input (it frees its mesh twice), it keeps global state, and it prints
// to stdout. So whatever TetGen does (self-intersecting or touching facets, features below its
// tolerance, refinement that does not terminate, a crash), the caller's process is unharmed and
// gets a MeshError that quotes TetGen's last printed lines; nothing reaches the caller's stdout.
// Calls may run concurrently from several threads. Cost: one fork and a temporary file holding
// the result (about 24 bytes per output point and 16 per tetrahedron) per call.
#pragma once

#include <string>

#include "pliant/host/fem/surface_io.hpp"
#include "pliant/host/recording.hpp"

namespace pliant::host {

struct TetrahedralizeOptions {
  /// Quality refinement (TetGen -q): add points until every tetrahedron's circumradius is at
  /// most this times its shortest edge. 0 turns refinement off; otherwise in [1, 1e6]. TetGen's
  /// refinement is not guaranteed to terminate for bounds much below its default of 2.0 (see
  /// timeout_s).
  double max_radius_edge_ratio = 2.0;
  /// Together with quality refinement: the smallest dihedral angle allowed (degrees, TetGen
  /// -q<ratio>/<angle>). 0 leaves TetGen's default. Must be in [0, 70); large values may not
  /// terminate.
  double min_dihedral_angle_deg = 0.0;
  /// Maximum tetrahedron volume (surface units cubed, TetGen -a). 0 means unbounded; otherwise
  /// in [1e-30, 1e30]. Every output tetrahedron's volume is at most this.
  double max_tet_volume = 0.0;
  /// Keep the input surface triangles unsplit (TetGen -Y): the boundary of the mesh is exactly
  /// the input surface, with no points added on it. Refinement then only adds interior points.
  bool preserve_surface = false;
  /// TetGen -Q: no progress report. TetGen's output never reaches stdout either way (see top);
  /// only its last lines are quoted in an error.
  bool quiet = true;
  /// Stop TetGen after this many seconds (rounded up) and throw MeshError; 0 means no limit.
  /// Must be in [0, 1e6].
  double timeout_s = 0.0;
};

/// The TetGen switch string built from `options` ("pzQq2a0.5" and so on; always p, z).
/// Throws MeshError naming the first invalid option.
std::string tetgen_switches(const TetrahedralizeOptions& options);

/// Tetrahedralizes the volume enclosed by `surface`, which must be closed (require_closed_surface)
/// and free of self-intersections and duplicate points (merge_duplicate_vertices). Returns a mesh
/// whose points start with the surface points that the mesh uses (in their order; a point TetGen
/// did not use is dropped) followed by the points TetGen added; every tetrahedron positively
/// oriented (mesh_io.hpp), no unused points, youngs_modulus empty. Errors name `file_label`.
TetMesh tetrahedralize(const TriangleSurface& surface, const TetrahedralizeOptions& options = TetrahedralizeOptions(),
                       const std::string& file_label = "surface");

}  // namespace pliant::host
