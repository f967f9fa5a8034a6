// Structured box meshes and 1:8 refinement (fem_box_mesh.hpp).
#include "pliant/host/fem/fem_box_mesh.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <unordered_map>

#include <Eigen/Dense>

namespace pliant::host::fem {

namespace {

std::size_t uz(int i) { return static_cast<std::size_t>(i); }

Eigen::Vector3d point(const TetMesh& mesh, int i) {
  return Eigen::Vector3d(mesh.points[uz(3 * i)], mesh.points[uz(3 * i + 1)], mesh.points[uz(3 * i + 2)]);
}

double signed_volume6(const TetMesh& mesh, const std::array<int, 4>& t) {
  const Eigen::Vector3d x0 = point(mesh, t[0]);
  Eigen::Matrix3d d;
  d << point(mesh, t[1]) - x0, point(mesh, t[2]) - x0, point(mesh, t[3]) - x0;
  return d.determinant();
}

// Appends the tetrahedron, swapping two corners if needed for a positive orientation.
void push_oriented(TetMesh& mesh, std::array<int, 4> t) {
  if (signed_volume6(mesh, t) < 0) std::swap(t[2], t[3]);
  mesh.tetrahedra.insert(mesh.tetrahedra.end(), t.begin(), t.end());
}

}  // namespace

TetMesh make_box_tet_mesh(const Eigen::Vector3d& size_m, const std::array<int, 3>& cells, BoxSplit split,
                          const Eigen::Vector3d& origin_m) {
  if (!(size_m.array() > 0).all() || !size_m.allFinite() || !origin_m.allFinite()) {
    throw std::invalid_argument("make_box_tet_mesh: sizes must be positive and finite");
  }
  if (cells[0] < 1 || cells[1] < 1 || cells[2] < 1)
    throw std::invalid_argument("make_box_tet_mesh: cells must be >= 1");
  const int nx = cells[0] + 1;
  const int ny = cells[1] + 1;
  const int nz = cells[2] + 1;
  TetMesh mesh;
  mesh.points.reserve(uz(3 * nx * ny * nz));
  for (int k = 0; k < nz; ++k) {
    for (int j = 0; j < ny; ++j) {
      for (int i = 0; i < nx; ++i) {
        mesh.points.push_back(origin_m.x() + size_m.x() * i / cells[0]);
        mesh.points.push_back(origin_m.y() + size_m.y() * j / cells[1]);
        mesh.points.push_back(origin_m.z() + size_m.z() * k / cells[2]);
      }
    }
  }
  auto id = [&](int i, int j, int k) { return (k * ny + j) * nx + i; };
  // The six monotone paths from corner (0,0,0) to (1,1,1) of a unit cell (axis orders).
  constexpr int kOrders[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  mesh.tetrahedra.reserve(uz(24 * cells[0] * cells[1] * cells[2]));
  for (int ck = 0; ck < cells[2]; ++ck) {
    for (int cj = 0; cj < cells[1]; ++cj) {
      for (int ci = 0; ci < cells[0]; ++ci) {
        const std::array<int, 3> base = {ci, cj, ck};
        std::array<bool, 3> mirror = {false, false, false};
        if (split == BoxSplit::mirrored_kuhn) mirror = {ci % 2 == 1, cj % 2 == 1, ck % 2 == 1};
        auto corner = [&](const std::array<int, 3>& local) {
          std::array<int, 3> g{};
          for (int a = 0; a < 3; ++a) g[uz(a)] = base[uz(a)] + (mirror[uz(a)] ? 1 - local[uz(a)] : local[uz(a)]);
          return id(g[0], g[1], g[2]);
        };
        for (const auto& order : kOrders) {
          std::array<int, 3> local = {0, 0, 0};
          std::array<int, 4> t{};
          t[0] = corner(local);
          for (int s = 0; s < 3; ++s) {
            local[uz(order[s])] = 1;
            t[uz(s + 1)] = corner(local);
          }
          push_oriented(mesh, t);
        }
      }
    }
  }
  return mesh;
}

TetMesh refine_tet_mesh(const TetMesh& mesh) {
  if (mesh.points.size() % 3 != 0 || mesh.tetrahedra.size() % 4 != 0) {
    throw std::invalid_argument("refine_tet_mesh: malformed mesh arrays");
  }
  const int n = mesh.point_count();
  const int m = mesh.tet_count();
  if (!mesh.youngs_modulus.empty() && static_cast<int>(mesh.youngs_modulus.size()) != m) {
    throw std::invalid_argument("refine_tet_mesh: youngs_modulus size does not match the tetrahedra");
  }
  TetMesh out;
  out.points = mesh.points;
  std::unordered_map<std::int64_t, int> midpoint;
  midpoint.reserve(uz(7 * m));
  auto mid = [&](int a, int b) {
    if (a > b) std::swap(a, b);
    const std::int64_t key = static_cast<std::int64_t>(a) * n + b;
    const auto found = midpoint.find(key);
    if (found != midpoint.end()) return found->second;
    const int index = out.point_count();
    for (int d = 0; d < 3; ++d) out.points.push_back(0.5 * (mesh.points[uz(3 * a + d)] + mesh.points[uz(3 * b + d)]));
    midpoint.emplace(key, index);
    return index;
  };
  out.tetrahedra.reserve(uz(32 * m));
  for (int e = 0; e < m; ++e) {
    std::array<int, 4> v{};
    for (int a = 0; a < 4; ++a) {
      v[uz(a)] = mesh.tetrahedra[uz(4 * e + a)];
      if (v[uz(a)] < 0 || v[uz(a)] >= n) throw std::invalid_argument("refine_tet_mesh: index out of range");
    }
    const int m01 = mid(v[0], v[1]);
    const int m02 = mid(v[0], v[2]);
    const int m03 = mid(v[0], v[3]);
    const int m12 = mid(v[1], v[2]);
    const int m13 = mid(v[1], v[3]);
    const int m23 = mid(v[2], v[3]);
    push_oriented(out, {v[0], m01, m02, m03});
    push_oriented(out, {m01, v[1], m12, m13});
    push_oriented(out, {m02, m12, v[2], m23});
    push_oriented(out, {m03, m13, m23, v[3]});
    // Inner octahedron: opposite vertex pairs (m01, m23), (m02, m13), (m03, m12); cut along the
    // shortest, the other four vertices form the equator cycle around it.
    const std::array<std::array<int, 6>, 3> cuts = {
        {{m01, m23, m02, m03, m13, m12}, {m02, m13, m01, m03, m23, m12}, {m03, m12, m01, m02, m23, m13}}};
    int best = 0;
    double best_length = HUGE_VAL;
    for (int c = 0; c < 3; ++c) {
      const double length = (point(out, cuts[uz(c)][0]) - point(out, cuts[uz(c)][1])).squaredNorm();
      if (length < best_length) {
        best_length = length;
        best = c;
      }
    }
    const auto& cut = cuts[uz(best)];
    for (int q = 0; q < 4; ++q) push_oriented(out, {cut[0], cut[1], cut[uz(2 + q)], cut[uz(2 + (q + 1) % 4)]});
    if (!mesh.youngs_modulus.empty())
      out.youngs_modulus.insert(out.youngs_modulus.end(), 8, mesh.youngs_modulus[uz(e)]);
  }
  return out;
}

std::vector<int> points_on_plane(const TetMesh& mesh, int axis, double value_m, double tolerance_m) {
  if (axis < 0 || axis > 2) throw std::invalid_argument("points_on_plane: axis must be 0, 1 or 2");
  std::vector<int> out;
  for (int i = 0; i < mesh.point_count(); ++i) {
    if (std::abs(mesh.points[uz(3 * i + axis)] - value_m) <= tolerance_m) out.push_back(i);
  }
  return out;
}

}  // namespace pliant::host::fem
