// Legacy VTK writer for the tetrahedral rest mesh of a recording (mesh.vtk, recording format
// v1). The reader is parse_vtk_tet_mesh in recording.hpp; it reads back exactly what this writes.
#pragma once

#include <iosfwd>

#include "pliant/host/recording.hpp"

namespace pliant::host {

/// Writes `mesh` as legacy VTK 3.0 ASCII UNSTRUCTURED_GRID: `POINTS n double`, classic
/// `CELLS m 5m` with cell type 10, and `CELL_DATA` scalars `youngs_modulus` when the mesh has
/// them. Numbers use the shortest text that reads back bit for bit. Throws std::runtime_error
/// when the mesh arrays are inconsistent (points not a multiple of 3, tetrahedra not a multiple
/// of 4, an index out of range, youngs_modulus neither empty nor one per tetrahedron). Stream
/// failures are left in the state of `out` for the caller to check.
void write_vtk_tet_mesh(const TetMesh& mesh, std::ostream& out);

}  // namespace pliant::host
