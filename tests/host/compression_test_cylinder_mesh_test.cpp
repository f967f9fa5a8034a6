// Cylinder tetrahedral mesher: volume and its convergence, orientation, conformity, boundary
// area, numbering and element quality (smallest dihedral angle).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <iostream>
#include <map>
#include <stdexcept>
#include <vector>

#include "pliant/host/fem/cylinder_mesh.hpp"

namespace pliant::host {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDiameter = 0.05;
constexpr double kHeight = 0.03;
constexpr double kRadius = 0.5 * kDiameter;

using Vec = std::array<double, 3>;

Vec point(const TetMesh& m, int i) {
  const auto at = 3 * static_cast<std::size_t>(i);
  return {m.points[at], m.points[at + 1], m.points[at + 2]};
}
Vec sub(const Vec& a, const Vec& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
Vec cross(const Vec& a, const Vec& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
double dot(const Vec& a, const Vec& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
double norm(const Vec& a) { return std::sqrt(dot(a, a)); }

int tet_index(const TetMesh& m, int tet, int k) { return m.tetrahedra[static_cast<std::size_t>(4 * tet + k)]; }

double mesh_volume(const TetMesh& m) {
  double volume = 0.0;
  for (int t = 0; t < m.tet_count(); ++t) volume += tet_signed_volume(m, t);
  return volume;
}

// Smallest interior dihedral angle over all tetrahedra, in degrees.
double min_dihedral_degrees(const TetMesh& m) {
  double smallest = 180.0;
  for (int t = 0; t < m.tet_count(); ++t) {
    Vec p[4];
    for (int k = 0; k < 4; ++k) p[k] = point(m, tet_index(m, t, k));
    Vec normal[4];  // outward unit normal of the face opposite point k
    for (int k = 0; k < 4; ++k) {
      const Vec& a = p[(k + 1) % 4];
      Vec n = cross(sub(p[(k + 2) % 4], a), sub(p[(k + 3) % 4], a));
      const double sign = dot(n, sub(p[k], a)) > 0.0 ? -1.0 : 1.0;
      const double length = norm(n);
      for (double& c : n) c *= sign / length;
      normal[k] = n;
    }
    for (int i = 0; i < 4; ++i) {
      for (int j = i + 1; j < 4; ++j) {
        const double c = std::clamp(dot(normal[i], normal[j]), -1.0, 1.0);
        smallest = std::min(smallest, 180.0 - std::acos(c) * 180.0 / kPi);
      }
    }
  }
  return smallest;
}

// The inscribed c-gon's share of the circle's area.
double polygon_ratio(int c) { return c / (2.0 * kPi) * std::sin(2.0 * kPi / c); }

TEST(CylinderMesh, SizesAndNumberingAsDocumented) {
  const TetMesh m = cylinder_tet_mesh(kDiameter, kHeight, 2, 24, 5);
  EXPECT_EQ(m.point_count(), 582);
  EXPECT_EQ(m.tet_count(), 2520);
  EXPECT_TRUE(m.youngs_modulus.empty());
  const int per_level = 97;  // (24/4 + 1)^2 + 2 * 24
  const int axis = 3 * 7 + 3;
  for (int level = 0; level <= 5; ++level) {
    const Vec a = point(m, level * per_level + axis);
    EXPECT_EQ(a[0], 0.0);
    EXPECT_EQ(a[1], 0.0);
  }
  for (int i = 0; i < per_level; ++i) {
    EXPECT_EQ(point(m, i)[2], 0.0);
    EXPECT_EQ(point(m, m.point_count() - 1 - i)[2], kHeight);
  }
  for (int i = per_level; i < m.point_count() - per_level; ++i) {
    const double z = point(m, i)[2];
    EXPECT_GT(z, 0.0);
    EXPECT_LT(z, kHeight);
  }
  // The last section nodes of each level are the lateral surface, exactly on the circle.
  for (int b = 0; b < 24; ++b) {
    const Vec p = point(m, per_level - 24 + b);
    EXPECT_NEAR(std::hypot(p[0], p[1]), kRadius, 1e-15);
  }
}

TEST(CylinderMesh, VolumeWithinOnePercentAtModerateResolutionAndConvergesMonotonically) {
  const TetMesh moderate = cylinder_tet_mesh(kDiameter, kHeight, 3, 32, 6);
  const double exact = kPi * kRadius * kRadius * kHeight;
  EXPECT_NEAR(mesh_volume(moderate) / exact, 1.0, 0.01) << moderate.tet_count() << " tetrahedra";

  double previous = 0.0;
  for (const int c : {8, 16, 24, 32, 48, 64}) {
    const TetMesh m = cylinder_tet_mesh(kDiameter, kHeight, c / 8, c, 4);
    const double ratio = mesh_volume(m) / exact;
    EXPECT_NEAR(ratio, polygon_ratio(c), 1e-12) << "c = " << c;
    EXPECT_GT(ratio, previous) << "c = " << c;
    EXPECT_LT(ratio, 1.0);
    previous = ratio;
  }
  EXPECT_GT(previous, 0.998);
}

TEST(CylinderMesh, EveryTetrahedronHasPositiveVolume) {
  for (const auto& d :
       {CylinderMeshDivisions{1, 8, 1}, CylinderMeshDivisions{2, 24, 5}, CylinderMeshDivisions{5, 40, 3}}) {
    const TetMesh m = cylinder_tet_mesh(kDiameter, kHeight, d);
    const double typical = mesh_volume(m) / m.tet_count();
    for (int t = 0; t < m.tet_count(); ++t) {
      EXPECT_GT(tet_signed_volume(m, t), 0.02 * typical) << "tet " << t;
    }
  }
}

TEST(CylinderMesh, ConformingWithTheCylinderAsBoundary) {
  const int c = 24;
  const TetMesh m = cylinder_tet_mesh(kDiameter, kHeight, 2, c, 5);
  std::map<std::array<int, 3>, int> faces;
  for (int t = 0; t < m.tet_count(); ++t) {
    for (int k = 0; k < 4; ++k) {
      std::array<int, 3> face = {tet_index(m, t, (k + 1) % 4), tet_index(m, t, (k + 2) % 4),
                                 tet_index(m, t, (k + 3) % 4)};
      std::sort(face.begin(), face.end());
      ++faces[face];
    }
  }
  double boundary_area = 0.0;
  int interior = 0;
  for (const auto& [face, count] : faces) {
    ASSERT_LE(count, 2) << "a triangle shared by more than two tetrahedra";
    const Vec a = point(m, face[0]);
    const Vec b = point(m, face[1]);
    const Vec p = point(m, face[2]);
    if (count == 2) {
      ++interior;
      continue;
    }
    // A boundary triangle lies on a cap or on the lateral surface.
    const bool bottom = a[2] == 0.0 && b[2] == 0.0 && p[2] == 0.0;
    const bool top = a[2] == kHeight && b[2] == kHeight && p[2] == kHeight;
    const auto on_circle = [](const Vec& v) { return std::fabs(std::hypot(v[0], v[1]) - kRadius) < 1e-12; };
    EXPECT_TRUE(bottom || top || (on_circle(a) && on_circle(b) && on_circle(p)));
    boundary_area += 0.5 * norm(cross(sub(b, a), sub(p, a)));
  }
  EXPECT_GT(interior, 0);
  const double caps = 2.0 * 0.5 * c * kRadius * kRadius * std::sin(2.0 * kPi / c);
  const double lateral = c * 2.0 * kRadius * std::sin(kPi / c) * kHeight;
  EXPECT_NEAR(boundary_area, caps + lateral, 1e-12 * (caps + lateral));
  const double continuum = 2.0 * kPi * kRadius * kRadius + 2.0 * kPi * kRadius * kHeight;
  EXPECT_NEAR(boundary_area / continuum, 1.0, 0.02);
}

TEST(CylinderMesh, NoSlivers) {
  struct Expected {
    CylinderMeshDivisions divisions;
    double min_degrees;
  };
  for (const Expected& e : {Expected{{2, 24, 5}, 20.0}, Expected{{2, 16, 6}, 20.0}, Expected{{3, 24, 6}, 20.0},
                            Expected{{4, 32, 8}, 20.0}, Expected{{6, 48, 12}, 20.0}}) {
    const TetMesh m = cylinder_tet_mesh(kDiameter, kHeight, e.divisions);
    const double smallest = min_dihedral_degrees(m);
    std::cout << "[ quality  ] (" << e.divisions.radial << ", " << e.divisions.circumferential << ", "
              << e.divisions.axial << "): " << m.tet_count() << " tetrahedra, smallest dihedral angle " << smallest
              << " degrees\n";
    EXPECT_GE(smallest, e.min_degrees);
  }
}

TEST(CylinderMesh, RefusesBadArguments) {
  EXPECT_THROW(cylinder_tet_mesh(kDiameter, kHeight, 2, 12, 5), std::invalid_argument);
  EXPECT_THROW(cylinder_tet_mesh(kDiameter, kHeight, 2, 0, 5), std::invalid_argument);
  EXPECT_THROW(cylinder_tet_mesh(kDiameter, kHeight, 0, 24, 5), std::invalid_argument);
  EXPECT_THROW(cylinder_tet_mesh(kDiameter, kHeight, 2, 24, 0), std::invalid_argument);
  EXPECT_THROW(cylinder_tet_mesh(std::nan(""), kHeight, 2, 24, 5), std::invalid_argument);
  EXPECT_THROW(cylinder_tet_mesh(kDiameter, -kHeight, 2, 24, 5), std::invalid_argument);
  EXPECT_THROW(cylinder_tet_mesh(kDiameter, kHeight, 1000, 4000, 1000), std::invalid_argument);
}

TEST(CylinderMesh, SignedVolumeOfTheUnitTetrahedron) {
  TetMesh m;
  m.points = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
  m.tetrahedra = {0, 1, 2, 3};
  EXPECT_DOUBLE_EQ(tet_signed_volume(m, 0), 1.0 / 6.0);
  m.tetrahedra = {0, 2, 1, 3};
  EXPECT_DOUBLE_EQ(tet_signed_volume(m, 0), -1.0 / 6.0);
}

}  // namespace
}  // namespace pliant::host
