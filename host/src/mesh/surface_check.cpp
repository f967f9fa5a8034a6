// Vertex merging, edge census and enclosed volume of triangle surfaces.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <tuple>
#include <unordered_map>
#include <vector>

#include "mesh_text.hpp"
#include "pliant/host/fem/surface_io.hpp"

namespace pliant::host {
namespace {

using mesh_detail::fail_file;

struct CellKey {
  std::int64_t x, y, z;
  bool operator==(const CellKey& other) const { return x == other.x && y == other.y && z == other.z; }
};

struct CellHash {
  std::size_t operator()(const CellKey& key) const {
    auto mix = [](std::uint64_t h, std::int64_t v) {
      h ^= static_cast<std::uint64_t>(v) + 0x9e3779b97f4a7c15ull + (h << 6) + (h >> 2);
      return h;
    };
    return static_cast<std::size_t>(mix(mix(mix(0, key.x), key.y), key.z));
  }
};

void check_surface_arrays(const TriangleSurface& surface, const std::string& label) {
  if (surface.points.size() % 3 != 0 || surface.triangles.size() % 3 != 0) {
    fail_file(label, "points or triangles have a partial entry");
  }
  const std::size_t count = surface.points.size() / 3;
  if (count > 2147483647u) fail_file(label, "too many points for int indices");
  for (std::size_t i = 0; i < surface.points.size(); ++i) {
    if (!std::isfinite(surface.points[i])) {
      fail_file(label, "point " + std::to_string(i / 3) + " has a non-finite coordinate");
    }
  }
  for (std::size_t i = 0; i < surface.triangles.size(); ++i) {
    const int index = surface.triangles[i];
    if (index < 0 || static_cast<std::size_t>(index) >= count) {
      fail_file(label, "triangle " + std::to_string(i / 3) + ": point index " + std::to_string(index) +
                           " out of range (" + std::to_string(count) + " points)");
    }
  }
}

}  // namespace

SurfaceMergeResult merge_duplicate_vertices(TriangleSurface& surface, const std::string& file_label,
                                            double relative_tolerance) {
  check_surface_arrays(surface, file_label);
  if (!(relative_tolerance == 0.0 || (relative_tolerance >= 1e-15 && relative_tolerance <= 0.1))) {
    fail_file(file_label, "merge tolerance must be 0 or in [1e-15, 0.1]");
  }
  const std::size_t count = surface.points.size() / 3;
  const double* p = surface.points.data();
  double low[3] = {0.0, 0.0, 0.0};
  double high[3] = {0.0, 0.0, 0.0};
  for (std::size_t i = 0; i < count; ++i) {
    for (std::size_t axis = 0; axis < 3; ++axis) {
      const double v = p[3 * i + axis];
      if (i == 0 || v < low[axis]) low[axis] = v;
      if (i == 0 || v > high[axis]) high[axis] = v;
    }
  }
  const double diagonal = std::hypot(high[0] - low[0], high[1] - low[1], high[2] - low[2]);
  const double tolerance = relative_tolerance * diagonal;

  // Representative (first point of its group) for every point.
  std::vector<int> representative(count);
  std::unordered_map<CellKey, std::vector<int>, CellHash> grid;
  grid.reserve(count);
  const double cell = tolerance > 0.0 ? tolerance : 1.0;
  for (std::size_t i = 0; i < count; ++i) {
    const double* q = p + 3 * i;
    int found = -1;
    if (tolerance > 0.0) {
      const CellKey key{static_cast<std::int64_t>(std::floor((q[0] - low[0]) / cell)),
                        static_cast<std::int64_t>(std::floor((q[1] - low[1]) / cell)),
                        static_cast<std::int64_t>(std::floor((q[2] - low[2]) / cell))};
      const double limit_sq = tolerance * tolerance;
      for (std::int64_t dx = -1; dx <= 1 && found < 0; ++dx) {
        for (std::int64_t dy = -1; dy <= 1 && found < 0; ++dy) {
          for (std::int64_t dz = -1; dz <= 1 && found < 0; ++dz) {
            const auto it = grid.find(CellKey{key.x + dx, key.y + dy, key.z + dz});
            if (it == grid.end()) continue;
            for (const int j : it->second) {
              const double* r = p + 3 * static_cast<std::size_t>(j);
              const double ex = q[0] - r[0];
              const double ey = q[1] - r[1];
              const double ez = q[2] - r[2];
              if (ex * ex + ey * ey + ez * ez <= limit_sq) {
                found = j;
                break;
              }
            }
          }
        }
      }
      if (found < 0) grid[key].push_back(static_cast<int>(i));
    } else {
      // Exact: the cell is the coordinates themselves (+0.0 folds -0.0 into 0.0).
      std::int64_t bits[3];
      for (std::size_t axis = 0; axis < 3; ++axis) {
        const double v = q[axis] + 0.0;
        std::memcpy(&bits[axis], &v, sizeof v);
      }
      const CellKey exact{bits[0], bits[1], bits[2]};
      auto& bucket = grid[exact];
      if (!bucket.empty()) {
        found = bucket.front();
      } else {
        bucket.push_back(static_cast<int>(i));
      }
    }
    representative[i] = found >= 0 ? found : static_cast<int>(i);
  }

  SurfaceMergeResult result;
  std::vector<int> triangles;
  triangles.reserve(surface.triangles.size());
  for (std::size_t t = 0; t + 2 < surface.triangles.size(); t += 3) {
    const int a = representative[static_cast<std::size_t>(surface.triangles[t])];
    const int b = representative[static_cast<std::size_t>(surface.triangles[t + 1])];
    const int c = representative[static_cast<std::size_t>(surface.triangles[t + 2])];
    if (a == b || b == c || a == c) {
      ++result.triangles_dropped;
      continue;
    }
    triangles.push_back(a);
    triangles.push_back(b);
    triangles.push_back(c);
  }

  // Compact: keep used representatives in file order.
  std::vector<int> new_index(count, -1);
  for (const int index : triangles) new_index[static_cast<std::size_t>(index)] = 0;
  std::vector<double> points;
  int next = 0;
  for (std::size_t i = 0; i < count; ++i) {
    if (new_index[i] < 0) continue;
    new_index[i] = next++;
    points.insert(points.end(), p + 3 * i, p + 3 * i + 3);
  }
  for (int& index : triangles) index = new_index[static_cast<std::size_t>(index)];
  result.points_removed = static_cast<int>(count) - next;
  surface.points = std::move(points);
  surface.triangles = std::move(triangles);
  return result;
}

SurfaceEdgeCheck check_surface_edges(const TriangleSurface& surface) {
  // (low, high, forward) per triangle side; forward when the side runs low -> high.
  std::vector<std::tuple<int, int, int>> sides;
  sides.reserve(surface.triangles.size());
  for (std::size_t t = 0; t + 2 < surface.triangles.size(); t += 3) {
    for (std::size_t k = 0; k < 3; ++k) {
      const int a = surface.triangles[t + k];
      const int b = surface.triangles[t + (k + 1) % 3];
      sides.emplace_back(std::min(a, b), std::max(a, b), a < b ? 1 : 0);
    }
  }
  std::sort(sides.begin(), sides.end());
  SurfaceEdgeCheck check;
  std::size_t i = 0;
  while (i < sides.size()) {
    std::size_t j = i;
    int forward = 0;
    while (j < sides.size() && std::get<0>(sides[j]) == std::get<0>(sides[i]) &&
           std::get<1>(sides[j]) == std::get<1>(sides[i])) {
      forward += std::get<2>(sides[j]);
      ++j;
    }
    const std::size_t uses = j - i;
    ++check.edges;
    const bool bad = uses != 2;
    if (uses == 1) ++check.boundary_edges;
    if (uses >= 3) ++check.nonmanifold_edges;
    if (uses == 2 && forward != 1) ++check.misoriented_edges;
    if (bad && check.first_bad_edge[0] < 0) {
      check.first_bad_edge[0] = std::get<0>(sides[i]);
      check.first_bad_edge[1] = std::get<1>(sides[i]);
    }
    i = j;
  }
  return check;
}

void require_closed_surface(const TriangleSurface& surface, const std::string& file_label) {
  check_surface_arrays(surface, file_label);
  if (surface.triangles.empty()) fail_file(file_label, "the surface has no triangles");
  const SurfaceEdgeCheck check = check_surface_edges(surface);
  if (check.closed()) return;
  const auto* p = surface.points.data();
  const auto a = static_cast<std::size_t>(check.first_bad_edge[0]);
  const auto b = static_cast<std::size_t>(check.first_bad_edge[1]);
  auto at = [&](std::size_t i) {
    return "(" + mesh_detail::format_double(p[3 * i]) + ", " + mesh_detail::format_double(p[3 * i + 1]) + ", " +
           mesh_detail::format_double(p[3 * i + 2]) + ")";
  };
  fail_file(file_label, "surface is not closed: " + std::to_string(check.boundary_edges) +
                            " boundary edge(s) (used by one triangle), " + std::to_string(check.nonmanifold_edges) +
                            " non-manifold edge(s) (used by three or more); first between "
                            "points " +
                            std::to_string(a) + " " + at(a) + " and " + std::to_string(b) + " " + at(b));
}

double surface_enclosed_volume(const TriangleSurface& surface) {
  double sum = 0.0;
  const double* p = surface.points.data();
  for (std::size_t t = 0; t + 2 < surface.triangles.size(); t += 3) {
    const double* a = p + 3 * static_cast<std::size_t>(surface.triangles[t]);
    const double* b = p + 3 * static_cast<std::size_t>(surface.triangles[t + 1]);
    const double* c = p + 3 * static_cast<std::size_t>(surface.triangles[t + 2]);
    sum += a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) + a[2] * (b[0] * c[1] - b[1] * c[0]);
  }
  return sum / 6.0;
}

}  // namespace pliant::host
