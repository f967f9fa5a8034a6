// Closed triangle surfaces for tetrahedralization: readers for Wavefront OBJ, PLY and STL, vertex
// merging and a closedness check.
//
// Host code only: these functions allocate and throw MeshError (mesh_io.hpp), whose what() is one
// line naming the file, the line (text) or byte offset (binary), and the cause. Counts in a file
// are checked against the bytes left before anything is allocated.
//
// Units are whatever the file uses; nothing is scaled.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "pliant/host/fem/mesh_io.hpp"

namespace pliant::host {

/// A triangle soup or mesh: point i is row i of `points`; triangles hold 0-based point indices,
/// three per triangle. Readers return distinct indices within each triangle.
struct TriangleSurface {
  std::vector<double> points;  ///< 3 * point_count, x y z per point
  std::vector<int> triangles;  ///< 3 * triangle_count point indices
  int point_count() const { return static_cast<int>(points.size() / 3); }
  int triangle_count() const { return static_cast<int>(triangles.size() / 3); }
};

// ------------------------------------------------------------------------------------------
// Readers. They return the file's vertices as stored (STL: three new points per triangle), with
// no merging; read_surface merges.

/// Wavefront OBJ: "v x y z [w | r g b]" and "f" with "i", "i/t", "i//n" or "i/t/n" references,
/// 1-based, or negative (relative to the vertices read so far). Polygons of n >= 3 vertices are
/// split into a fan of n - 2 triangles from their first vertex. vt, vn, vp, g, o, s, l, p,
/// usemtl, mtllib and '#' comments are ignored; any other statement is an error (free-form
/// curves and surfaces are not supported). A face repeating a vertex is an error.
TriangleSurface parse_obj(std::string_view text, const std::string& file_label);

/// PLY 1.0, format ascii, binary_little_endian or binary_big_endian. The "vertex" element must
/// have properties x, y, z (any scalar type); the "face" element a list property vertex_indices
/// (or vertex_index) of any integer types. Other elements and properties are read and skipped.
/// Faces of n >= 3 vertices are fan-triangulated as in OBJ.
TriangleSurface parse_ply(std::string_view text, const std::string& file_label);

/// STL, ASCII ("solid ... facet normal ... outer loop, 3 vertex lines, endloop, endfacet ...
/// endsolid", several solids allowed) or binary (80-byte header, little-endian uint32 count,
/// 50 bytes per triangle). A file is binary when its size is exactly 84 + 50 * count, whatever
/// its first bytes say (some binary writers start the header with "solid"). Normals and the
/// attribute bytes are ignored; orientation comes from the vertex order.
TriangleSurface parse_stl(std::string_view text, const std::string& file_label);

/// Reads .obj, .ply or .stl by extension (case-insensitive), then merge_duplicate_vertices with
/// the default tolerance and require_closed_surface. What merging changed (points merged,
/// collapsed triangles dropped) is appended to `warnings` when given. Throws MeshError.
TriangleSurface read_surface(const std::string& path, std::vector<std::string>* warnings = nullptr);

// ------------------------------------------------------------------------------------------
// Checks

struct SurfaceMergeResult {
  int points_removed = 0;     ///< merged into an earlier point, or used by no triangle
  int triangles_dropped = 0;  ///< collapsed: two of their points merged
};

/// Merges points closer than `relative_tolerance` times the diagonal of the points' bounding
/// box (0 merges only identical coordinates; otherwise it must be in [1e-15, 0.1]), keeping the
/// first point of each group in file order, drops triangles that collapse (two of their points
/// merge; STL files often hold such slivers) and drops points no triangle uses. Throws MeshError
/// naming `file_label` when an index is out of range or a coordinate is not finite. O(n)
/// expected (a hash grid).
SurfaceMergeResult merge_duplicate_vertices(TriangleSurface& surface, const std::string& file_label,
                                            double relative_tolerance = 1e-9);

/// Edge census of a surface: an edge is a pair of points joined by a triangle side.
struct SurfaceEdgeCheck {
  int edges = 0;                     ///< distinct undirected edges
  int boundary_edges = 0;            ///< used by exactly one triangle (a hole)
  int nonmanifold_edges = 0;         ///< used by three or more triangles
  int misoriented_edges = 0;         ///< used twice in the same direction (neighbours wound apart)
  int first_bad_edge[2] = {-1, -1};  ///< points of the first boundary or non-manifold edge
  bool closed() const { return boundary_edges == 0 && nonmanifold_edges == 0; }
};

/// Counts edges by how many triangles use them. O(triangles log triangles).
SurfaceEdgeCheck check_surface_edges(const TriangleSurface& surface);

/// Throws MeshError ("<label>: surface is not closed: 3 boundary edges, 0 non-manifold edges,
/// first edge between points 4 and 9 at (x, y, z)") unless every edge is used by exactly two
/// triangles and there is at least one triangle.
void require_closed_surface(const TriangleSurface& surface, const std::string& file_label);

/// Signed volume enclosed by a closed surface (divergence theorem): positive when the triangles
/// are wound counter-clockwise seen from outside. Meaningless for open surfaces.
double surface_enclosed_volume(const TriangleSurface& surface);

}  // namespace pliant::host
