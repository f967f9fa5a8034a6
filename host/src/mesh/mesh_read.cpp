// File entry points: read_mesh_file, read_tet_mesh (format by extension) and read_surface.
#include <cerrno>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <system_error>
#include <vector>

#include "mesh_text.hpp"
#include "pliant/host/fem/mesh_io.hpp"
#include "pliant/host/fem/surface_io.hpp"
#include "pliant/host/fem/tetrahedralize.hpp"
#include "pliant/host/recording.hpp"

namespace pliant::host {
namespace {

namespace fs = std::filesystem;
using mesh_detail::fail_file;

constexpr std::uintmax_t kMaxMeshFileBytes = std::uintmax_t{1} << 31;

std::string lower_extension(const fs::path& path) {
  std::string extension = path.extension().string();
  for (char& c : extension) c = mesh_detail::lower(c);
  return extension;
}

// The file with `path`'s stem and the other TetGen extension, in the same case style.
fs::path tetgen_sibling(const fs::path& path, bool want_node) {
  const std::string extension = path.extension().string();
  const bool upper = !extension.empty() && extension.size() > 1 && extension[1] >= 'A' && extension[1] <= 'Z';
  fs::path sibling = path;
  sibling.replace_extension(want_node ? (upper ? ".NODE" : ".node") : (upper ? ".ELE" : ".ele"));
  return sibling;
}

void add_merge_warnings(const std::string& label, const SurfaceMergeResult& merged,
                        std::vector<std::string>* warnings) {
  if (warnings == nullptr) return;
  if (merged.points_removed > 0) {
    warnings->push_back(label + ": " + std::to_string(merged.points_removed) +
                        " surface point(s) merged into coincident points or unused, removed");
  }
  if (merged.triangles_dropped > 0) {
    warnings->push_back(label + ": " + std::to_string(merged.triangles_dropped) +
                        " degenerate surface triangle(s) (two coincident corners) dropped");
  }
}

}  // namespace

std::string read_mesh_file(const std::string& path) {
  std::error_code error;
  if (!fs::is_regular_file(path, error)) {
    fail_file(path, fs::exists(path, error) ? "not a regular file" : "no such file");
  }
  const std::uintmax_t size = fs::file_size(path, error);
  if (error) fail_file(path, "cannot read: " + error.message());
  if (size > kMaxMeshFileBytes) {
    fail_file(path, "file too large (" + std::to_string(size) + " bytes, the limit is " +
                        std::to_string(kMaxMeshFileBytes) + ")");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) fail_file(path, std::string("cannot open: ") + std::strerror(errno));
  std::string text(static_cast<std::size_t>(size), '\0');
  in.read(text.data(), static_cast<std::streamsize>(size));
  if (in.gcount() != static_cast<std::streamsize>(size)) {
    fail_file(path, "cannot read: the file changed or an I/O error occurred");
  }
  return text;
}

TriangleSurface read_surface(const std::string& path, std::vector<std::string>* warnings) {
  const std::string extension = lower_extension(path);
  TriangleSurface surface;
  if (extension == ".obj") {
    surface = parse_obj(read_mesh_file(path), path);
  } else if (extension == ".ply") {
    surface = parse_ply(read_mesh_file(path), path);
  } else if (extension == ".stl") {
    surface = parse_stl(read_mesh_file(path), path);
  } else {
    fail_file(path,
              "unknown surface extension '" + mesh_detail::printable(extension) + "' (expected .obj, .ply or .stl)");
  }
  const SurfaceMergeResult merged = merge_duplicate_vertices(surface, path);
  add_merge_warnings(path, merged, warnings);
  require_closed_surface(surface, path);
  return surface;
}

TetMesh read_tet_mesh(const std::string& path, MeshReadReport* report) {
  if (report != nullptr) *report = MeshReadReport();
  const std::string extension = lower_extension(path);
  if (extension == ".msh") return parse_msh(read_mesh_file(path), path, report);
  if (extension == ".vtk") {
    TetMesh mesh;
    try {
      mesh = parse_vtk_tet_mesh(read_mesh_file(path), path);
    } catch (const RecordingError& error) {
      throw MeshError(error.what());
    }
    orient_and_check_tet_mesh(mesh, path, report);
    return mesh;
  }
  if (extension == ".node" || extension == ".ele") {
    const fs::path node = extension == ".node" ? fs::path(path) : tetgen_sibling(path, true);
    const fs::path ele = extension == ".ele" ? fs::path(path) : tetgen_sibling(path, false);
    TetGenNodes nodes = parse_tetgen_node(read_mesh_file(node.string()), node.string());
    return parse_tetgen_ele(read_mesh_file(ele.string()), ele.string(), std::move(nodes), report);
  }
  if (extension == ".obj" || extension == ".ply" || extension == ".stl") {
    std::vector<std::string> warnings;
    const TriangleSurface surface = read_surface(path, &warnings);
    TetMesh mesh = tetrahedralize(surface, TetrahedralizeOptions(), path);
    if (report != nullptr) report->warnings = std::move(warnings);
    return mesh;
  }
  fail_file(path, "unknown mesh extension '" + mesh_detail::printable(extension) +
                      "' (expected .msh, .vtk, .node, .ele, .obj, .ply or .stl)");
}

}  // namespace pliant::host
