// Tetrahedral meshes for the FEM: readers for gmsh MSH, legacy VTK and TetGen .node/.ele files,
// closed triangle surfaces (OBJ, PLY, STL) tetrahedralized on the fly, and small writers for MSH
// 4.1 and TetGen. Every reader returns the recording's TetMesh type (recording.hpp): point i is
// row i of `points`, `tetrahedra` holds 0-based point indices, four per tetrahedron.
//
// Host code only: these functions allocate and throw.
//
// What every reader guarantees about the mesh it returns (and what a user will notice):
//  - Orientation: every tetrahedron (a, b, c, d) has positive signed volume
//    (b - a) . ((c - a) x (d - a)) / 6 > 0. A tetrahedron stored the other way round is fixed by
//    swapping its last two points; the number fixed is MeshReadReport::reoriented_tets.
//  - Degenerate tetrahedra (a repeated point, or |6 V| <= 1e-12 * (longest edge)^3) are an
//    error, not dropped.
//  - Unused points (referenced by no tetrahedron) are kept, so point numbering matches the file;
//    their number is MeshReadReport::unused_points and a warning names the first one.
//  - Coordinates are finite; NaN or infinite coordinates are an error.
//  - youngs_modulus is filled only by the VTK reader (CELL_DATA youngs_modulus); MSH and TetGen
//    files leave it empty (their region attributes are ignored).
//
// Element types (MSH): only linear tetrahedra (gmsh type 4) are kept. Points, lines and surface
// elements (any element of an entity of dimension 0-2, e.g. the boundary triangles gmsh writes)
// are skipped and counted in MeshReadReport::skipped_elements. Any other volume element
// (second-order 10-node tetrahedra, type 11, hexahedra, prisms, pyramids) is an error that names
// the type: its midside nodes would otherwise become unused points and its curved geometry
// would be lost. Export linear elements (gmsh -order 1). TetGen .ele files with 10 nodes per
// tetrahedron (-o2) are refused for the same reason.
//
// Errors: readers throw MeshError whose what() is exactly one line naming the file, the line
// (text formats) or byte offset (binary formats), and the cause, e.g.
//   "bar.msh:12: node tag 9 is not defined in $Nodes"
//   "part.ply: byte 1043: unexpected end of file in face 17 (of 20)"
//   "bar.ele:4: tetrahedron 2 has zero volume (degenerate)"
// Counts in a file are checked against the bytes left before anything is allocated, so a
// corrupt count cannot make a reader allocate more than a small multiple of the file size.
#pragma once

#include <iosfwd>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "pliant/host/recording.hpp"

namespace pliant::host {

/// A malformed or unsupported mesh or surface file, or an invalid mesh. what() is one line.
class MeshError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// What a reader changed or noticed while reading a mesh. Readers take an optional pointer to
/// one; the report is reset by the reader before it is filled.
struct MeshReadReport {
  int reoriented_tets = 0;            ///< tetrahedra whose last two points were swapped (see top)
  int unused_points = 0;              ///< points kept although no tetrahedron uses them
  int skipped_elements = 0;           ///< MSH points/lines/surface elements skipped
  std::vector<std::string> warnings;  ///< one line each, naming the file
};

// ------------------------------------------------------------------------------------------
// Files

/// Reads a tetrahedral mesh, choosing the format by the extension of `path` (case-insensitive):
///   .msh          gmsh MSH 4.1 (ASCII or binary) or MSH 2.2 (ASCII)
///   .vtk          legacy VTK ASCII UNSTRUCTURED_GRID of tetrahedra (parse_vtk_tet_mesh), then
///                 oriented and checked like the other formats
///   .node / .ele  TetGen; given either, the other is the sibling with the same stem
///   .obj .ply .stl  a closed triangle surface (surface_io.hpp), merged and tetrahedralized
///                 with default TetrahedralizeOptions (tetrahedralize.hpp)
/// Files larger than 2 GiB are refused. Throws MeshError (one line, naming the file).
TetMesh read_tet_mesh(const std::string& path, MeshReadReport* report = nullptr);

/// The whole file as bytes; MeshError naming `path` when it is missing, not a regular file,
/// unreadable or larger than 2 GiB.
std::string read_mesh_file(const std::string& path);

// ------------------------------------------------------------------------------------------
// Parsers over in-memory text (used by read_tet_mesh and the fuzz target). `file_label` names
// the file in error messages. Each throws MeshError on malformed input.

/// gmsh MSH 4.1 ASCII and binary (either byte order, size_t of 4 or 8 bytes), and MSH 2.2
/// ASCII. MSH 4.1: $Entities and any other section is skipped; node tags may be sparse and in
/// any order and are renumbered 0..n-1 in the order the nodes appear in $Nodes; parametric
/// node coordinates are accepted and ignored. $Nodes must come before $Elements, both exactly
/// once. Other versions (2.0-2.1 and 3.0 are not written by gmsh; 4.0 has a different layout,
/// binary 2.2) are refused with the version in the message.
TetMesh parse_msh(std::string_view text, const std::string& file_label, MeshReadReport* report = nullptr);

/// Points of a TetGen .node file and the number its first point carries (0 or 1), which the
/// .ele file's point references use as well.
struct TetGenNodes {
  std::vector<double> points;  ///< 3 * count
  int first_index = 1;
};

/// TetGen .node: "<count> 3 <attributes> <0|1 boundary markers>" then one point per line,
/// "<index> x y z [attributes...] [marker]". Points must be numbered consecutively from 0 or 1.
/// '#' starts a comment that runs to the end of the line; blank lines are ignored. Attributes
/// and markers are read and ignored. Dimension must be 3.
TetGenNodes parse_tetgen_node(std::string_view text, const std::string& file_label);

/// TetGen .ele: "<count> 4 <attributes>" then "<index> a b c d [attributes...]" per line, the
/// point references numbered as nodes.first_index says. Element indices are not checked beyond
/// being integers. Region attributes are ignored. Returns the mesh with nodes.points moved in.
TetMesh parse_tetgen_ele(std::string_view text, const std::string& file_label, TetGenNodes nodes,
                         MeshReadReport* report = nullptr);

// ------------------------------------------------------------------------------------------
// Writers. Numbers use the shortest text that reads back bit for bit. Each throws MeshError when
// the mesh arrays are inconsistent (partial entries, index out of range, non-finite point);
// stream failures are left in the stream's state for the caller to check. youngs_modulus is not
// written (neither format has a standard place for it).

/// MSH 4.1 ASCII: one volume entity, node tags 1..n, element tags 1..m, type 4.
void write_msh(const TetMesh& mesh, std::ostream& out);

/// TetGen .node ("n 3 0 0") and .ele ("m 4 0"), numbered from `first_index` (0 or 1).
void write_tetgen(const TetMesh& mesh, std::ostream& node_out, std::ostream& ele_out, int first_index = 1);

// ------------------------------------------------------------------------------------------
// Geometry

/// Sum of the signed volumes of all tetrahedra (point units cubed), each positive for the
/// orientation above. Precondition: indices in range (not checked). O(tet_count). (The volume of
/// one tetrahedron is tet_signed_volume in cylinder_mesh.hpp.)
double tet_mesh_volume(const TetMesh& mesh);

/// The checks every reader applies, for meshes built in memory: array sizes, indices in range,
/// finite points, youngs_modulus empty or one per tetrahedron, then orientation fixed and
/// degenerate tetrahedra rejected as described at the top of this file. Messages name
/// `file_label` and the 0-based tetrahedron index. Throws MeshError.
void orient_and_check_tet_mesh(TetMesh& mesh, const std::string& file_label, MeshReadReport* report = nullptr);

}  // namespace pliant::host
