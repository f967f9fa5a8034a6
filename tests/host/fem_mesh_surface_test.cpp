// Surfaces (OBJ, PLY, STL), vertex merging, closedness, and TetGen tetrahedralization of a box and
// an icosphere: volume against the divergence theorem, orientation, the volume bound, and mesh
// consistency.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "../support/temp_dir.hpp"
#include "pliant/host/fem/mesh_io.hpp"
#include "pliant/host/fem/surface_io.hpp"
#include "pliant/host/fem/tetrahedralize.hpp"

namespace pliant::host {
namespace {

double six_volume(const double* a, const double* b, const double* c, const double* d) {
  const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
  const double v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  const double w[3] = {d[0] - a[0], d[1] - a[1], d[2] - a[2]};
  return u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0]) + u[2] * (v[0] * w[1] - v[1] * w[0]);
}

const double* pt(const std::vector<double>& points, int i) { return &points[3 * static_cast<std::size_t>(i)]; }

// Independent oracle: enclosed volume of a closed, outward-wound triangle surface.
double enclosed_volume(const TriangleSurface& s) {
  const double origin[3] = {0.0, 0.0, 0.0};
  double sum = 0.0;
  for (std::size_t t = 0; t < s.triangles.size(); t += 3) {
    sum += six_volume(origin, pt(s.points, s.triangles[t]), pt(s.points, s.triangles[t + 1]),
                      pt(s.points, s.triangles[t + 2]));
  }
  return sum / 6.0;
}

struct MeshStats {
  double volume = 0.0;
  double max_tet_volume = 0.0;
  double min_tet_volume = 1e300;
  std::size_t boundary_faces = 0;
  std::size_t overshared_faces = 0;
  double boundary_volume = 0.0;
  std::size_t unused_points = 0;
};

MeshStats stats_of(const TetMesh& mesh) {
  MeshStats s;
  std::map<std::array<int, 3>, std::vector<std::array<int, 3>>> faces;
  static const int kFaces[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};
  std::vector<char> used(mesh.points.size() / 3, 0);
  for (std::size_t t = 0; t < mesh.tetrahedra.size(); t += 4) {
    const int* tet = &mesh.tetrahedra[t];
    for (int k = 0; k < 4; ++k) used[static_cast<std::size_t>(tet[k])] = 1;
    const double v =
        six_volume(pt(mesh.points, tet[0]), pt(mesh.points, tet[1]), pt(mesh.points, tet[2]), pt(mesh.points, tet[3])) /
        6.0;
    s.volume += v;
    s.max_tet_volume = std::max(s.max_tet_volume, v);
    s.min_tet_volume = std::min(s.min_tet_volume, v);
    for (const auto& f : kFaces) {
      std::array<int, 3> face = {tet[f[0]], tet[f[1]], tet[f[2]]};
      std::array<int, 3> key = face;
      std::sort(key.begin(), key.end());
      faces[key].push_back(face);
    }
  }
  const double origin[3] = {0.0, 0.0, 0.0};
  for (const auto& entry : faces) {
    if (entry.second.size() > 2) ++s.overshared_faces;
    if (entry.second.size() != 1) continue;
    ++s.boundary_faces;
    const auto& f = entry.second.front();
    s.boundary_volume += six_volume(origin, pt(mesh.points, f[0]), pt(mesh.points, f[1]), pt(mesh.points, f[2])) / 6.0;
  }
  for (const char u : used) s.unused_points += u == 0 ? 1 : 0;
  return s;
}

// An axis-aligned box, 12 outward triangles.
TriangleSurface box(double x0, double y0, double z0, double dx, double dy, double dz) {
  TriangleSurface s;
  for (int k = 0; k < 8; ++k) {
    s.points.push_back(x0 + ((k & 1) ? dx : 0.0));
    s.points.push_back(y0 + ((k & 2) ? dy : 0.0));
    s.points.push_back(z0 + ((k & 4) ? dz : 0.0));
  }
  // Quads (outward), split into two triangles each.
  const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& q : quads) {
    s.triangles.insert(s.triangles.end(), {q[0], q[1], q[2], q[0], q[2], q[3]});
  }
  return s;
}

// Icosahedron subdivided `levels` times, projected on a sphere of `radius` around `center`.
TriangleSurface icosphere(int levels, double radius, const double center[3]) {
  const double g = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<std::array<double, 3>> v = {{-1, g, 0},  {1, g, 0},  {-1, -g, 0}, {1, -g, 0}, {0, -1, g},  {0, 1, g},
                                          {0, -1, -g}, {0, 1, -g}, {g, 0, -1},  {g, 0, 1},  {-g, 0, -1}, {-g, 0, 1}};
  std::vector<std::array<int, 3>> f = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                       {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                       {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                       {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  auto normalize = [](std::array<double, 3> p) {
    const double n = std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
    return std::array<double, 3>{p[0] / n, p[1] / n, p[2] / n};
  };
  for (auto& p : v) p = normalize(p);
  for (int level = 0; level < levels; ++level) {
    std::map<std::pair<int, int>, int> midpoints;
    auto midpoint = [&](int a, int b) {
      const auto key = std::make_pair(std::min(a, b), std::max(a, b));
      const auto it = midpoints.find(key);
      if (it != midpoints.end()) return it->second;
      const auto& p = v[static_cast<std::size_t>(a)];
      const auto& q = v[static_cast<std::size_t>(b)];
      v.push_back(normalize({p[0] + q[0], p[1] + q[1], p[2] + q[2]}));
      const int index = static_cast<int>(v.size()) - 1;
      midpoints[key] = index;
      return index;
    };
    std::vector<std::array<int, 3>> next;
    for (const auto& t : f) {
      const int ab = midpoint(t[0], t[1]);
      const int bc = midpoint(t[1], t[2]);
      const int ca = midpoint(t[2], t[0]);
      next.push_back({t[0], ab, ca});
      next.push_back({t[1], bc, ab});
      next.push_back({t[2], ca, bc});
      next.push_back({ab, bc, ca});
    }
    f = next;
  }
  TriangleSurface s;
  for (const auto& p : v) {
    for (int k = 0; k < 3; ++k) s.points.push_back(center[k] + radius * p[static_cast<std::size_t>(k)]);
  }
  for (const auto& t : f) s.triangles.insert(s.triangles.end(), {t[0], t[1], t[2]});
  return s;
}

void write_text(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
}

// -------------------------------------------------------------------------------- readers

TEST(Obj, FormsNegativeIndicesPolygonsAndIgnoredStatements) {
  const std::string text =
      "# cube corner\nmtllib a.mtl\no thing\ng part\ns 1\n"
      "v 0 0 0\nv 1 0 0 1.0\nv 1 1 0 0.5 0.5 0.5\nv 0 1 0\n"
      "vt 0 0\nvn 0 0 1\nusemtl red\n"
      "f 1/1/1 2/1/1 3/1/1 4/1/1\n"
      "v 0 0 1\n"
      "f -5//1 -4//1 -1//1\n"
      "f 2/1 3/1 5/1 # a comment\n"
      "l 1 2\n";
  const TriangleSurface s = parse_obj(text, "t.obj");
  EXPECT_EQ(s.point_count(), 5);
  EXPECT_EQ(s.triangles, (std::vector<int>{0, 1, 2, 0, 2, 3, 0, 1, 4, 1, 2, 4}));
  EXPECT_EQ(s.points[3 * 1 + 0], 1.0);
}

std::string cube_ply_ascii() {
  return "ply\nformat ascii 1.0\ncomment made by hand\n"
         "element vertex 8\nproperty float x\nproperty float y\nproperty float z\n"
         "property uchar red\n"
         "element face 6\nproperty list uchar int vertex_indices\nproperty int flags\n"
         "element edge 1\nproperty int vertex1\nproperty int vertex2\n"
         "end_header\n"
         "0 0 0 255\n1 0 0 255\n1 1 0 255\n0 1 0 255\n0 0 1 255\n1 0 1 255\n1 1 1 255\n"
         "0 1 1 255\n"
         "4 0 3 2 1 7\n4 4 5 6 7 7\n4 0 1 5 4 7\n4 1 2 6 5 7\n4 2 3 7 6 7\n4 3 0 4 7 7\n"
         "0 1\n";
}

template <typename T>
void put(std::string& out, T value, bool big_endian) {
  unsigned char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  const std::uint16_t probe = 1;
  unsigned char first = 0;
  std::memcpy(&first, &probe, 1);
  if ((first == 1) == big_endian) std::reverse(bytes, bytes + sizeof(T));
  out.append(reinterpret_cast<const char*>(bytes), sizeof(T));
}

std::string cube_ply_binary(bool big_endian) {
  std::string out = std::string("ply\nformat ") + (big_endian ? "binary_big_endian" : "binary_little_endian") +
                    " 1.0\nelement vertex 8\nproperty double x\nproperty double y\n"
                    "property double z\nelement face 6\n"
                    "property list uchar uint vertex_index\nend_header\n";
  const TriangleSurface cube = box(0, 0, 0, 1, 1, 1);
  for (const double v : cube.points) put<double>(out, v, big_endian);
  const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& q : quads) {
    put<std::uint8_t>(out, 4, big_endian);
    for (const int i : q) put<std::uint32_t>(out, static_cast<std::uint32_t>(i), big_endian);
  }
  return out;
}

TEST(Ply, AsciiWithExtraPropertiesAndElements) {
  TriangleSurface s = parse_ply(cube_ply_ascii(), "c.ply");
  EXPECT_EQ(s.point_count(), 8);
  EXPECT_EQ(s.triangle_count(), 12);
  require_closed_surface(s, "c.ply");
  EXPECT_NEAR(enclosed_volume(s), 1.0, 1e-15);
  EXPECT_EQ(check_surface_edges(s).misoriented_edges, 0);
}

TEST(Ply, AsciiWithoutFinalNewline) {
  const std::string text =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
      "0 0 0 1 0 0 0 1 0 3 0 1 2";
  EXPECT_EQ(parse_ply(text, "t.ply").triangles, (std::vector<int>{0, 1, 2}));
}

TEST(Ply, BinaryBothByteOrders) {
  for (const bool big : {false, true}) {
    const TriangleSurface s = parse_ply(cube_ply_binary(big), "c.ply");
    EXPECT_EQ(s.points, box(0, 0, 0, 1, 1, 1).points) << big;
    EXPECT_EQ(s.triangle_count(), 12);
    EXPECT_NEAR(surface_enclosed_volume(s), 1.0, 1e-15);
  }
}

std::string cube_stl_ascii() {
  const TriangleSurface cube = box(0, 0, 0, 1, 1, 1);
  std::string out = "solid cube made by hand\n";
  for (std::size_t t = 0; t < cube.triangles.size(); t += 3) {
    out += "  facet normal 0 0 0\n    outer loop\n";
    for (std::size_t k = 0; k < 3; ++k) {
      const double* p = pt(cube.points, cube.triangles[t + k]);
      out += "      vertex " + std::to_string(p[0]) + " " + std::to_string(p[1]) + " " + std::to_string(p[2]) + "\n";
    }
    out += "    endloop\n  endfacet\n";
  }
  return out + "endsolid cube\n";
}

std::string cube_stl_binary() {
  const TriangleSurface cube = box(0, 0, 0, 1, 1, 1);
  std::string out = "solid binary header that starts like ASCII";
  out.resize(80, ' ');
  put<std::uint32_t>(out, 12, false);
  for (std::size_t t = 0; t < cube.triangles.size(); t += 3) {
    for (int k = 0; k < 3; ++k) put<float>(out, 0.0f, false);
    for (std::size_t k = 0; k < 3; ++k) {
      const double* p = pt(cube.points, cube.triangles[t + k]);
      for (int a = 0; a < 3; ++a) put<float>(out, static_cast<float>(p[a]), false);
    }
    put<std::uint16_t>(out, 0, false);
  }
  return out;
}

TEST(Stl, AsciiAndBinaryGiveTheSameMergedCube) {
  for (const std::string& text : {cube_stl_ascii(), cube_stl_binary()}) {
    TriangleSurface s = parse_stl(text, "c.stl");
    EXPECT_EQ(s.point_count(), 36);
    EXPECT_FALSE(check_surface_edges(s).closed());
    const SurfaceMergeResult merged = merge_duplicate_vertices(s, "c.stl");
    EXPECT_EQ(merged.points_removed, 28);
    EXPECT_EQ(merged.triangles_dropped, 0);
    EXPECT_EQ(s.point_count(), 8);
    require_closed_surface(s, "c.stl");
    EXPECT_NEAR(surface_enclosed_volume(s), 1.0, 1e-15);
  }
}

TEST(Merge, ToleranceIsRelativeToTheBoundingBox) {
  TriangleSurface s = box(0, 0, 0, 1000, 1000, 1000);
  // A copy of point 0 displaced by 1e-7 (1e-10 of the diagonal) and one by 1e-3.
  s.points.insert(s.points.end(), {1e-7, 0, 0, 1e-3, 0, 0});
  s.triangles[0] = 8;
  s.triangles[3] = 9;
  TriangleSurface exact = s;
  EXPECT_EQ(merge_duplicate_vertices(exact, "s", 0.0).points_removed, 0);
  const SurfaceMergeResult merged = merge_duplicate_vertices(s, "s");
  EXPECT_EQ(merged.points_removed, 1);  // point 8 merged into point 0; point 9 kept
  EXPECT_EQ(s.point_count(), 9);
  EXPECT_EQ(s.triangles[0], 0);
  EXPECT_EQ(s.triangles[3], 8);
}

TEST(Merge, CollapsedTrianglesAreDroppedAndCounted) {
  TriangleSurface s = box(0, 0, 0, 1, 1, 1);
  s.points.insert(s.points.end(), {0, 0, 0});        // point 8 == point 0
  s.triangles.insert(s.triangles.end(), {0, 8, 1});  // collapses after merging
  const SurfaceMergeResult merged = merge_duplicate_vertices(s, "s");
  EXPECT_EQ(merged.triangles_dropped, 1);
  EXPECT_EQ(merged.points_removed, 1);
  require_closed_surface(s, "s");
}

TEST(EdgeCheck, CountsMisorientedNeighbours) {
  TriangleSurface s = box(0, 0, 0, 1, 1, 1);
  std::swap(s.triangles[1], s.triangles[2]);  // flip one triangle
  const SurfaceEdgeCheck check = check_surface_edges(s);
  EXPECT_TRUE(check.closed());
  EXPECT_EQ(check.edges, 18);
  EXPECT_EQ(check.misoriented_edges, 3);
}

// -------------------------------------------------------------------------------- TetGen

TEST(TetgenSwitches, BuiltFromOptions) {
  TetrahedralizeOptions options;
  EXPECT_EQ(tetgen_switches(options), "pzQq2");
  options.max_radius_edge_ratio = 1.5;
  options.min_dihedral_angle_deg = 12.5;
  options.max_tet_volume = 0.000125;
  options.preserve_surface = true;
  options.quiet = false;
  EXPECT_EQ(tetgen_switches(options), "pzYq1.5/12.5a0.000125");
  options.max_radius_edge_ratio = 0.0;
  options.min_dihedral_angle_deg = 0.0;
  options.max_tet_volume = 0.0;
  EXPECT_EQ(tetgen_switches(options), "pzY");
  for (const auto& bad :
       {std::array<double, 3>{0.5, 0, 0}, std::array<double, 3>{2, 80, 0}, std::array<double, 3>{0, 10, 0},
        std::array<double, 3>{2, 0, -1}, std::array<double, 3>{2, 0, std::nan("")}}) {
    TetrahedralizeOptions o;
    o.max_radius_edge_ratio = bad[0];
    o.min_dihedral_angle_deg = bad[1];
    o.max_tet_volume = bad[2];
    EXPECT_THROW(tetgen_switches(o), MeshError) << bad[0] << " " << bad[1] << " " << bad[2];
  }
}

TEST(Tetrahedralize, BoxVolumeIsExact) {
  const TriangleSurface s = box(-0.25, 1.5, 3.0, 2.0, 0.75, 0.5);
  const double enclosed = enclosed_volume(s);
  EXPECT_NEAR(enclosed, 0.75, 1e-15);
  for (const bool refine : {false, true}) {
    TetrahedralizeOptions options;
    if (!refine) options.max_radius_edge_ratio = 0.0;
    if (refine) options.max_tet_volume = 0.01;
    const TetMesh mesh = tetrahedralize(s, options, "box");
    const MeshStats st = stats_of(mesh);
    EXPECT_NEAR(st.volume, enclosed, 1e-9 * enclosed) << refine;
    EXPECT_NEAR(tet_mesh_volume(mesh), enclosed, 1e-9 * enclosed);
    EXPECT_GT(st.min_tet_volume, 0.0);
    EXPECT_EQ(st.overshared_faces, 0u);
    EXPECT_EQ(st.unused_points, 0u);
    EXPECT_NEAR(st.boundary_volume, enclosed, 1e-9 * enclosed);
    if (refine) {
      EXPECT_LE(st.max_tet_volume, 0.01 * (1.0 + 1e-9));
      EXPECT_GE(mesh.tet_count(), 75);  // 0.75 / 0.01
    } else {
      EXPECT_EQ(mesh.point_count(), 8);  // no Steiner points without refinement
    }
  }
}

TEST(Tetrahedralize, IcosphereIsConsistentAndBounded) {
  const double center[3] = {0.1, -0.2, 0.3};
  const TriangleSurface s = icosphere(3, 0.05, center);  // 642 points, 1280 triangles
  ASSERT_EQ(s.triangle_count(), 1280);
  require_closed_surface(s, "sphere");
  const double enclosed = enclosed_volume(s);
  EXPECT_NEAR(surface_enclosed_volume(s), enclosed, 1e-12 * enclosed);
  EXPECT_LT(enclosed, 4.0 / 3.0 * 3.14159265358979323846 * 0.05 * 0.05 * 0.05);
  const double bound = enclosed / 500.0;
  struct Run {
    double ratio;
    double angle;
    double volume;
    bool preserve;
  };
  for (const Run& run : {Run{2.0, 0.0, 0.0, false}, Run{1.5, 10.0, bound, false}, Run{1.4, 0.0, bound, true}}) {
    TetrahedralizeOptions options;
    options.max_radius_edge_ratio = run.ratio;
    options.min_dihedral_angle_deg = run.angle;
    options.max_tet_volume = run.volume;
    options.preserve_surface = run.preserve;
    const TetMesh mesh = tetrahedralize(s, options, "sphere");
    const MeshStats st = stats_of(mesh);
    SCOPED_TRACE(tetgen_switches(options));
    EXPECT_NEAR(st.volume, enclosed, 1e-9 * enclosed);
    EXPECT_NEAR(st.boundary_volume, enclosed, 1e-9 * enclosed);
    EXPECT_GT(st.min_tet_volume, 0.0);
    EXPECT_EQ(st.overshared_faces, 0u);
    EXPECT_EQ(st.unused_points, 0u);
    if (run.volume > 0.0) {
      EXPECT_LE(st.max_tet_volume, run.volume * (1.0 + 1e-9));
      EXPECT_GE(static_cast<double>(mesh.tet_count()), enclosed / run.volume);
    }
    if (run.preserve) {
      // -Y: the boundary is exactly the input triangles and the input points come first.
      EXPECT_EQ(st.boundary_faces, 1280u);
      EXPECT_TRUE(std::equal(s.points.begin(), s.points.end(), mesh.points.begin()));
    }
  }
}

TEST(Tetrahedralize, RefusesOpenAndSelfIntersectingSurfaces) {
  TriangleSurface open = box(0, 0, 0, 1, 1, 1);
  open.triangles.resize(open.triangles.size() - 3);
  EXPECT_THROW(tetrahedralize(open), MeshError);

  TriangleSurface two = box(0, 0, 0, 1, 1, 1);
  const TriangleSurface other = box(0.5, 0.5, 0.5, 1, 1, 1);
  for (const double v : other.points) two.points.push_back(v);
  for (const int i : other.triangles) two.triangles.push_back(i + 8);
  std::string message;
  try {
    tetrahedralize(two, TetrahedralizeOptions(), "two.stl");
  } catch (const MeshError& error) {
    message = error.what();
  }
  // TetGen 1.5.0 detects the intersection and then crashes in its own cleanup; the child
  // process contains that (see tetrahedralize.hpp).
  EXPECT_EQ(message.rfind("two.stl: TetGen ", 0), 0u) << message;
  EXPECT_NE(message.find("the surface intersects itself"), std::string::npos) << message;
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
}

TEST(Tetrahedralize, TimeoutStopsRunawayRefinement) {
  const double center[3] = {0.0, 0.0, 0.0};
  TetrahedralizeOptions options;
  options.max_tet_volume = 1e-12;  // about 4e12 tetrahedra: cannot finish in a second
  options.timeout_s = 1.0;
  std::string message;
  try {
    tetrahedralize(icosphere(1, 1.0, center), options, "ball");
  } catch (const MeshError& error) {
    message = error.what();
  }
  EXPECT_EQ(message.rfind("ball: TetGen did not finish within timeout_s = 1 s", 0), 0u) << message;
}

TEST(ReadTetMesh, SurfaceFilesAreTetrahedralized) {
  test_support::TempDir dir("pliant_fem_mesh_");
  const std::pair<std::string, std::string> files[] = {
      {"cube.stl", cube_stl_ascii()},
      {"cube_binary.STL", cube_stl_binary()},
      {"cube.ply", cube_ply_ascii()},
      {"cube_be.ply", cube_ply_binary(true)},
      {"cube.obj",
       "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n"
       "f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n"}};
  for (const auto& file : files) {
    write_text(dir / file.first, file.second);
    MeshReadReport report;
    const TetMesh mesh = read_tet_mesh(dir / file.first, &report);
    EXPECT_NEAR(tet_mesh_volume(mesh), 1.0, 1e-9) << file.first;
    EXPECT_GT(stats_of(mesh).min_tet_volume, 0.0) << file.first;
    const bool stl = file.first.find(".stl") != std::string::npos || file.first.find(".STL") != std::string::npos;
    EXPECT_EQ(report.warnings.size(), stl ? 1u : 0u) << file.first;
  }
  std::vector<std::string> warnings;
  const TriangleSurface s = read_surface(dir / "cube.stl", &warnings);
  EXPECT_EQ(s.point_count(), 8);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("28 surface point(s) merged"), std::string::npos) << warnings[0];
}

}  // namespace
}  // namespace pliant::host
