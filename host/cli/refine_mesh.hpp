// `pliant refine --mesh FILE`: a tetrahedral mesh from a file in place of (or in the absence of)
// the recording's own mesh.vtk.
//
// Correspondence: mesh point i is particle i, as in recording-v1's mesh.vtk. A mesh may have
// more points than the recording has particles (a mesher adds interior points, and a
// tetrahedralized surface keeps its vertices first, in file order after merging duplicates):
// the extra points become particles that are never observed, with the default mass. A mesh
// with fewer points than particles is refused.
#pragma once

#include <string>
#include <vector>

#include "pliant/host/recording.hpp"

namespace pliant::cli {

/// Reads FILE with read_tet_mesh (.msh, .vtk, .node/.ele, or a closed .obj/.ply/.stl surface,
/// tetrahedralized) and makes it the recording's mesh and rest shape, extending the particles as
/// described above. Mesh warnings (reoriented or unused points, merged surface points) are
/// appended to `warnings`. Throws UsageError (one line naming the file) for an unreadable or
/// malformed mesh or one with fewer points than particles.
void attach_mesh(host::Recording& recording, const std::string& path, std::vector<std::string>& warnings);

}  // namespace pliant::cli
