#include "pliant/host/fem/cylinder_mesh.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace pliant::host {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Core half-width as a fraction of the radius, and how far its edges bulge toward the circle
// (0 a square, 1 the disc mapping). Chosen by measuring the smallest dihedral angle over the
// division counts the tests use: a smaller core squeezes the corner cells, a larger one the
// cells of the rings.
constexpr double kCoreFraction = 0.5;
constexpr double kCoreBulge = 0.5;

struct Point2 {
  double x = 0.0;
  double y = 0.0;
};

double distance(const Point2& a, const Point2& b) { return std::hypot(a.x - b.x, a.y - b.y); }

// The triangulated cross-section: node coordinates and counter-clockwise triangles.
struct Section {
  std::vector<Point2> nodes;
  std::vector<std::array<int, 3>> triangles;
};

// Adds the two triangles of the counter-clockwise quadrilateral a b c d, cut along its shorter
// diagonal (the one that keeps both triangles' angles furthest from 0 and 180 degrees here).
void add_quad(Section& section, int a, int b, int c, int d) {
  const auto& p = section.nodes;
  const double ac = distance(p[static_cast<std::size_t>(a)], p[static_cast<std::size_t>(c)]);
  const double bd = distance(p[static_cast<std::size_t>(b)], p[static_cast<std::size_t>(d)]);
  if (ac <= bd) {
    section.triangles.push_back({a, b, c});
    section.triangles.push_back({a, c, d});
  } else {
    section.triangles.push_back({a, b, d});
    section.triangles.push_back({b, c, d});
  }
}

Section o_grid_section(double radius, int radial, int circumferential) {
  const int m = circumferential / 4;  // core cells per side
  const int core_side = m + 1;
  Section section;
  section.nodes.reserve(static_cast<std::size_t>(core_side * core_side + radial * circumferential));
  const double half = kCoreFraction * radius;
  for (int j = 0; j <= m; ++j) {
    for (int i = 0; i <= m; ++i) {
      // Integer arithmetic first, so the centre node is exactly (0, 0).
      const double u = static_cast<double>(2 * i - m) / static_cast<double>(m);
      const double v = static_cast<double>(2 * j - m) / static_cast<double>(m);
      const double disc_u = u * std::sqrt(1.0 - 0.5 * v * v);
      const double disc_v = v * std::sqrt(1.0 - 0.5 * u * u);
      section.nodes.push_back({half * ((1.0 - kCoreBulge) * u + kCoreBulge * disc_u),
                               half * ((1.0 - kCoreBulge) * v + kCoreBulge * disc_v)});
    }
  }
  const auto core = [core_side](int i, int j) { return j * core_side + i; };
  for (int j = 0; j < m; ++j) {
    for (int i = 0; i < m; ++i) {
      add_quad(section, core(i, j), core(i + 1, j), core(i + 1, j + 1), core(i, j + 1));
    }
  }

  // The core's boundary counter-clockwise from its corner at -45 degrees: ring 0.
  std::vector<int> ring0;
  ring0.reserve(static_cast<std::size_t>(circumferential));
  for (int j = 0; j < m; ++j) ring0.push_back(core(m, j));
  for (int i = m; i > 0; --i) ring0.push_back(core(i, m));
  for (int j = m; j > 0; --j) ring0.push_back(core(0, j));
  for (int i = 0; i < m; ++i) ring0.push_back(core(i, 0));

  const auto ring = [&](int k, int b) {
    b %= circumferential;
    if (k == 0) return ring0[static_cast<std::size_t>(b)];
    return core_side * core_side + (k - 1) * circumferential + b;
  };
  for (int k = 1; k <= radial; ++k) {
    const double t = static_cast<double>(k) / static_cast<double>(radial);
    for (int b = 0; b < circumferential; ++b) {
      const Point2 inner = section.nodes[static_cast<std::size_t>(ring0[static_cast<std::size_t>(b)])];
      const double angle = -0.25 * kPi + 2.0 * kPi * static_cast<double>(b) / static_cast<double>(circumferential);
      const Point2 outer{radius * std::cos(angle), radius * std::sin(angle)};
      if (k == radial) {
        section.nodes.push_back(outer);  // exactly on the circle
      } else {
        section.nodes.push_back({inner.x + t * (outer.x - inner.x), inner.y + t * (outer.y - inner.y)});
      }
    }
  }
  for (int k = 0; k < radial; ++k) {
    for (int b = 0; b < circumferential; ++b) {
      add_quad(section, ring(k, b), ring(k + 1, b), ring(k + 1, b + 1), ring(k, b + 1));
    }
  }
  return section;
}

void check_dimension(double value, const char* name) {
  if (!std::isfinite(value) || !(value > 0.0)) {
    throw std::invalid_argument(std::string("cylinder_tet_mesh: ") + name + " must be finite and positive");
  }
}

}  // namespace

double tet_signed_volume(const TetMesh& mesh, int tet) {
  const auto first = static_cast<std::size_t>(4 * tet);
  std::array<const double*, 4> p{};
  for (std::size_t k = 0; k < 4; ++k) {
    p[k] = &mesh.points.at(3 * static_cast<std::size_t>(mesh.tetrahedra.at(first + k)));
  }
  const double a[3] = {p[1][0] - p[0][0], p[1][1] - p[0][1], p[1][2] - p[0][2]};
  const double b[3] = {p[2][0] - p[0][0], p[2][1] - p[0][1], p[2][2] - p[0][2]};
  const double c[3] = {p[3][0] - p[0][0], p[3][1] - p[0][1], p[3][2] - p[0][2]};
  const double det =
      a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) + a[2] * (b[0] * c[1] - b[1] * c[0]);
  return det / 6.0;
}

TetMesh cylinder_tet_mesh(double diameter_m, double height_m, int radial_divisions, int circumferential_divisions,
                          int axial_layers) {
  check_dimension(diameter_m, "diameter_m");
  check_dimension(height_m, "height_m");
  if (radial_divisions < 1) throw std::invalid_argument("cylinder_tet_mesh: radial_divisions must be >= 1");
  if (circumferential_divisions < 8 || circumferential_divisions % 8 != 0) {
    throw std::invalid_argument("cylinder_tet_mesh: circumferential_divisions must be a multiple of 8, >= 8");
  }
  if (axial_layers < 1) throw std::invalid_argument("cylinder_tet_mesh: axial_layers must be >= 1");
  // Tetrahedra = 6 * (c^2/16 + r c) * layers; checked in floating point so nothing overflows.
  const double c = circumferential_divisions;
  const double tets = 6.0 * (c * c / 16.0 + static_cast<double>(radial_divisions) * c) * axial_layers;
  if (tets > static_cast<double>(kMaxCylinderTets)) {
    throw std::invalid_argument("cylinder_tet_mesh: " + std::to_string(static_cast<long long>(tets)) +
                                " tetrahedra exceed the limit of " + std::to_string(kMaxCylinderTets));
  }

  const Section section = o_grid_section(0.5 * diameter_m, radial_divisions, circumferential_divisions);
  const int per_level = static_cast<int>(section.nodes.size());
  TetMesh mesh;
  mesh.points.reserve(3 * section.nodes.size() * static_cast<std::size_t>(axial_layers + 1));
  for (int level = 0; level <= axial_layers; ++level) {
    const double z =
        level == axial_layers ? height_m : height_m * static_cast<double>(level) / static_cast<double>(axial_layers);
    for (const Point2& node : section.nodes) {
      mesh.points.push_back(node.x);
      mesh.points.push_back(node.y);
      mesh.points.push_back(z);
    }
  }

  mesh.tetrahedra.reserve(12 * section.triangles.size() * static_cast<std::size_t>(axial_layers));
  for (int level = 0; level < axial_layers; ++level) {
    const int below = level * per_level;
    const int above = below + per_level;
    for (std::array<int, 3> t : section.triangles) {
      std::sort(t.begin(), t.end());
      const int a = t[0], b = t[1], cc = t[2];
      // With a < b < c, the side face (p, q), p < q, is cut from p below to q above.
      const std::array<std::array<int, 4>, 3> split = {{
          {below + a, below + b, below + cc, above + cc},
          {below + a, below + b, above + cc, above + b},
          {below + a, above + b, above + cc, above + a},
      }};
      for (const std::array<int, 4>& tet : split) {
        const std::size_t first = mesh.tetrahedra.size();
        mesh.tetrahedra.insert(mesh.tetrahedra.end(), tet.begin(), tet.end());
        if (tet_signed_volume(mesh, static_cast<int>(first / 4)) < 0.0) {
          std::swap(mesh.tetrahedra[first + 2], mesh.tetrahedra[first + 3]);
        }
      }
    }
  }
  return mesh;
}

}  // namespace pliant::host
