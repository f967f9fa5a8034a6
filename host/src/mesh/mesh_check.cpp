// Orientation, degeneracy and unused-point checks shared by every mesh reader, and mesh volume.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <string>
#include <utility>
#include <vector>

#include "mesh_text.hpp"
#include "pliant/host/fem/mesh_io.hpp"

namespace pliant::host {
namespace mesh_detail {
namespace {

// |6V| at or below this times the cube of the longest edge counts as flat. Rounding alone makes
// the determinant of a flat tetrahedron about 1e-16 L^3, so 1e-12 only catches true
// degeneracies, not thin but valid slivers.
constexpr double kFlatRelative = 1e-12;

double six_volume(const double* a, const double* b, const double* c, const double* d, double& longest_edge_sq) {
  const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
  const double v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  const double w[3] = {d[0] - a[0], d[1] - a[1], d[2] - a[2]};
  const double* p[4] = {a, b, c, d};
  longest_edge_sq = 0.0;
  for (int i = 0; i < 4; ++i) {
    for (int j = i + 1; j < 4; ++j) {
      const double dx = p[i][0] - p[j][0];
      const double dy = p[i][1] - p[j][1];
      const double dz = p[i][2] - p[j][2];
      longest_edge_sq = std::max(longest_edge_sq, dx * dx + dy * dy + dz * dz);
    }
  }
  return u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0]) + u[2] * (v[0] * w[1] - v[1] * w[0]);
}

const double* point(const double* points, int index) { return points + 3 * static_cast<std::size_t>(index); }

}  // namespace

TetShape classify_tet(const double* points, const int* tet) {
  for (int i = 0; i < 4; ++i) {
    for (int j = i + 1; j < 4; ++j) {
      if (tet[i] == tet[j]) return TetShape::repeated_point;
    }
  }
  double longest_sq = 0.0;
  const double det = six_volume(point(points, tet[0]), point(points, tet[1]), point(points, tet[2]),
                                point(points, tet[3]), longest_sq);
  const double scale = longest_sq * std::sqrt(longest_sq);
  if (!(std::fabs(det) > kFlatRelative * scale)) return TetShape::degenerate;
  return det > 0.0 ? TetShape::positive : TetShape::negative;
}

std::string orient_tet(const double* points, int* tet, std::size_t tet_number, MeshReadReport* report) {
  switch (classify_tet(points, tet)) {
    case TetShape::positive: return std::string();
    case TetShape::negative:
      std::swap(tet[2], tet[3]);
      if (report != nullptr) ++report->reoriented_tets;
      return std::string();
    case TetShape::repeated_point: return "tetrahedron " + std::to_string(tet_number) + " repeats a point (degenerate)";
    case TetShape::degenerate: break;
  }
  return "tetrahedron " + std::to_string(tet_number) + " has zero volume (degenerate: its four points are coplanar)";
}

void finish_report(const TetMesh& mesh, const std::string& label, MeshReadReport* report) {
  if (mesh.tetrahedra.empty()) fail_file(label, "the mesh has no tetrahedra");
  if (report == nullptr) return;
  std::vector<char> used(mesh.points.size() / 3, 0);
  for (const int index : mesh.tetrahedra) used[static_cast<std::size_t>(index)] = 1;
  std::size_t first_unused = used.size();
  int unused = 0;
  for (std::size_t i = 0; i < used.size(); ++i) {
    if (used[i] == 0) {
      if (unused == 0) first_unused = i;
      ++unused;
    }
  }
  report->unused_points = unused;
  if (unused > 0) {
    report->warnings.push_back(label + ": " + std::to_string(unused) +
                               " point(s) are used by no tetrahedron and were kept (first: "
                               "point " +
                               std::to_string(first_unused) + ", 0-based)");
  }
  if (report->reoriented_tets > 0) {
    report->warnings.push_back(label + ": " + std::to_string(report->reoriented_tets) +
                               " tetrahedra were negatively oriented and had their last two "
                               "points swapped");
  }
}

void check_writable(const TetMesh& mesh, const char* writer) {
  if (mesh.points.size() % 3 != 0 || mesh.tetrahedra.size() % 4 != 0) {
    fail_file(writer, "points or tetrahedra have a partial entry");
  }
  const std::size_t points = mesh.points.size() / 3;
  for (std::size_t i = 0; i < mesh.points.size(); ++i) {
    if (!std::isfinite(mesh.points[i])) {
      fail_file(writer, "point " + std::to_string(i / 3) + " is not finite");
    }
  }
  for (const int index : mesh.tetrahedra) {
    if (index < 0 || static_cast<std::size_t>(index) >= points) {
      fail_file(writer, "point index " + std::to_string(index) + " out of range");
    }
  }
}

}  // namespace mesh_detail

double tet_mesh_volume(const TetMesh& mesh) {
  const double* p = mesh.points.data();
  double sum = 0.0;
  for (std::size_t t = 0; t + 3 < mesh.tetrahedra.size(); t += 4) {
    const int* tet = mesh.tetrahedra.data() + t;
    double longest_sq = 0.0;
    sum += mesh_detail::six_volume(mesh_detail::point(p, tet[0]), mesh_detail::point(p, tet[1]),
                                   mesh_detail::point(p, tet[2]), mesh_detail::point(p, tet[3]), longest_sq);
  }
  return sum / 6.0;
}

void orient_and_check_tet_mesh(TetMesh& mesh, const std::string& file_label, MeshReadReport* report) {
  using mesh_detail::fail_file;
  if (report != nullptr) *report = MeshReadReport();
  if (mesh.points.size() % 3 != 0) fail_file(file_label, "points hold a partial x y z entry");
  if (mesh.tetrahedra.size() % 4 != 0) {
    fail_file(file_label, "tetrahedra hold a partial entry (not a multiple of 4 indices)");
  }
  const std::size_t points = mesh.points.size() / 3;
  const std::size_t tets = mesh.tetrahedra.size() / 4;
  if (points > static_cast<std::size_t>(2147483647) || tets > static_cast<std::size_t>(536870911)) {
    fail_file(file_label, "the mesh is too large for int indices");
  }
  if (!mesh.youngs_modulus.empty() && mesh.youngs_modulus.size() != tets) {
    fail_file(file_label, "youngs_modulus must be empty or hold one value per tetrahedron");
  }
  for (std::size_t i = 0; i < mesh.points.size(); ++i) {
    if (!std::isfinite(mesh.points[i])) {
      fail_file(file_label, "point " + std::to_string(i / 3) + " has a non-finite coordinate");
    }
  }
  for (std::size_t t = 0; t < tets; ++t) {
    int* tet = mesh.tetrahedra.data() + 4 * t;
    for (int k = 0; k < 4; ++k) {
      if (tet[k] < 0 || static_cast<std::size_t>(tet[k]) >= points) {
        fail_file(file_label, "tetrahedron " + std::to_string(t) + ": point index " + std::to_string(tet[k]) +
                                  " out of range (the mesh has " + std::to_string(points) + " points)");
      }
    }
    const std::string cause = mesh_detail::orient_tet(mesh.points.data(), tet, t, report);
    if (!cause.empty()) fail_file(file_label, cause);
  }
  mesh_detail::finish_report(mesh, file_label, report);
}

}  // namespace pliant::host
