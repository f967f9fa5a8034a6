// libFuzzer target for the mesh and surface readers (host/src/fem): gmsh MSH, TetGen .node/.ele,
// OBJ, PLY and STL, plus vertex merging and the closedness check on every surface read.
//
// Input: the first byte picks the reader (value % 6): 0 MSH, 1 TetGen (.node text, a NUL, .ele
// text), 2 OBJ, 3 PLY, 4 STL, 5 all of them on the same bytes. Every reader must either succeed
// or throw MeshError with a one-line message; any other exception escapes to libFuzzer, and
// sanitizer findings abort. Successful reads are checked for the invariants the FEM relies on.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <utility>

#include "pliant/host/fem/mesh_io.hpp"
#include "pliant/host/fem/surface_io.hpp"

namespace {

using pliant::host::MeshError;
using pliant::host::MeshReadReport;
using pliant::host::TetMesh;
using pliant::host::TriangleSurface;

void check_message(const MeshError& error) {
  const char* message = error.what();
  if (message[0] == '\0' || std::strchr(message, '\n') != nullptr) __builtin_trap();
}

template <typename Parse>
void attempt(Parse&& parse) {
  try {
    parse();
  } catch (const MeshError& error) {
    check_message(error);
  }
}

// Every tetrahedron in range, with four distinct points and positive volume; points finite.
void check_mesh(const TetMesh& mesh, const MeshReadReport& report) {
  if (mesh.points.size() % 3 != 0 || mesh.tetrahedra.size() % 4 != 0 || mesh.tetrahedra.empty()) {
    __builtin_trap();
  }
  const std::size_t points = mesh.points.size() / 3;
  for (const double value : mesh.points) {
    if (!std::isfinite(value)) __builtin_trap();
  }
  for (std::size_t t = 0; t < mesh.tetrahedra.size(); t += 4) {
    const double* p[4];
    for (std::size_t k = 0; k < 4; ++k) {
      const int index = mesh.tetrahedra[t + k];
      if (index < 0 || static_cast<std::size_t>(index) >= points) __builtin_trap();
      p[k] = &mesh.points[3 * static_cast<std::size_t>(index)];
    }
    const double u[3] = {p[1][0] - p[0][0], p[1][1] - p[0][1], p[1][2] - p[0][2]};
    const double v[3] = {p[2][0] - p[0][0], p[2][1] - p[0][1], p[2][2] - p[0][2]};
    const double w[3] = {p[3][0] - p[0][0], p[3][1] - p[0][1], p[3][2] - p[0][2]};
    const double det =
        u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0]) + u[2] * (v[0] * w[1] - v[1] * w[0]);
    if (!(det > 0.0)) __builtin_trap();
  }
  if (report.unused_points < 0 || static_cast<std::size_t>(report.unused_points) > points ||
      report.reoriented_tets < 0 || report.skipped_elements < 0) {
    __builtin_trap();
  }
  for (const std::string& warning : report.warnings) {
    if (warning.find('\n') != std::string::npos) __builtin_trap();
  }
}

void check_surface(TriangleSurface surface, const char* label) {
  const std::size_t points = surface.points.size() / 3;
  if (surface.points.size() % 3 != 0 || surface.triangles.size() % 3 != 0) __builtin_trap();
  for (const int index : surface.triangles) {
    if (index < 0 || static_cast<std::size_t>(index) >= points) __builtin_trap();
  }
  attempt([&] {
    pliant::host::merge_duplicate_vertices(surface, label);
    const pliant::host::SurfaceEdgeCheck edges = pliant::host::check_surface_edges(surface);
    if (edges.boundary_edges > edges.edges || edges.nonmanifold_edges > edges.edges) {
      __builtin_trap();
    }
    pliant::host::require_closed_surface(surface, label);
    if (!std::isfinite(pliant::host::surface_enclosed_volume(surface))) __builtin_trap();
  });
}

void run_msh(std::string_view text) {
  attempt([&] {
    MeshReadReport report;
    const TetMesh mesh = pliant::host::parse_msh(text, "fuzz.msh", &report);
    check_mesh(mesh, report);
  });
}

void run_tetgen(std::string_view text) {
  const std::size_t separator = text.find('\0');
  const std::string_view node = text.substr(0, separator);
  const std::string_view ele = separator == std::string_view::npos ? std::string_view() : text.substr(separator + 1);
  attempt([&] {
    pliant::host::TetGenNodes nodes = pliant::host::parse_tetgen_node(node, "fuzz.node");
    MeshReadReport report;
    const TetMesh mesh = pliant::host::parse_tetgen_ele(ele, "fuzz.ele", std::move(nodes), &report);
    check_mesh(mesh, report);
  });
}

void run_surface(std::string_view text, int kind) {
  attempt([&] {
    if (kind == 2) check_surface(pliant::host::parse_obj(text, "fuzz.obj"), "fuzz.obj");
    if (kind == 3) check_surface(pliant::host::parse_ply(text, "fuzz.ply"), "fuzz.ply");
    if (kind == 4) check_surface(pliant::host::parse_stl(text, "fuzz.stl"), "fuzz.stl");
  });
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const int selector = data[0] % 6;
  const std::string_view text(reinterpret_cast<const char*>(data + 1), size - 1);
  if (selector == 0 || selector == 5) run_msh(text);
  if (selector == 1 || selector == 5) run_tetgen(text);
  for (int kind = 2; kind <= 4; ++kind) {
    if (selector == kind || selector == 5) run_surface(text, kind);
  }
  return 0;
}
