// Mesh readers and writers: the IPC gmsh meshes (examples/meshes/tetmesh_ipc), MSH 4.1 ASCII and
// binary, MSH 2.2, TetGen .node/.ele, legacy VTK through read_tet_mesh, orientation repair,
// unused points, and writer round trips.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <functional>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "../support/temp_dir.hpp"
#include "pliant/host/fem/mesh_io.hpp"
#include "pliant/host/vtk_mesh.hpp"

namespace pliant::host {
namespace {

const std::string kDataDir = PLIANT_MESH_DATA_DIR;

std::string read_all(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream out;
  out << in.rdbuf();
  return out.str();
}

void write_all(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
}

// Signed volume of tetrahedron t, computed independently of the library.
double volume_of(const TetMesh& mesh, std::size_t t) {
  const auto p = [&](std::size_t k) { return &mesh.points[3 * static_cast<std::size_t>(mesh.tetrahedra[4 * t + k])]; };
  const double* a = p(0);
  const double* b = p(1);
  const double* c = p(2);
  const double* d = p(3);
  const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
  const double v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  const double w[3] = {d[0] - a[0], d[1] - a[1], d[2] - a[2]};
  return (u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0]) +
          u[2] * (v[0] * w[1] - v[1] * w[0])) /
         6.0;
}

// Faces used by one tetrahedron, wound outwards, and the enclosed volume they give by the
// divergence theorem; also checks that no face is shared by more than two tetrahedra.
double boundary_volume(const TetMesh& mesh, std::size_t& boundary_faces) {
  std::map<std::array<int, 3>, std::vector<std::array<int, 3>>> faces;
  // Faces of tetrahedron (a, b, c, d) wound outwards for positive orientation.
  static const int kFaces[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};
  for (std::size_t t = 0; t < mesh.tetrahedra.size() / 4; ++t) {
    for (const auto& f : kFaces) {
      std::array<int, 3> face = {mesh.tetrahedra[4 * t + static_cast<std::size_t>(f[0])],
                                 mesh.tetrahedra[4 * t + static_cast<std::size_t>(f[1])],
                                 mesh.tetrahedra[4 * t + static_cast<std::size_t>(f[2])]};
      std::array<int, 3> key = face;
      std::sort(key.begin(), key.end());
      faces[key].push_back(face);
    }
  }
  double volume = 0.0;
  boundary_faces = 0;
  for (const auto& entry : faces) {
    EXPECT_LE(entry.second.size(), 2u) << "a face is shared by more than two tetrahedra";
    if (entry.second.size() != 1) continue;
    ++boundary_faces;
    const auto& f = entry.second.front();
    const double* a = &mesh.points[3 * static_cast<std::size_t>(f[0])];
    const double* b = &mesh.points[3 * static_cast<std::size_t>(f[1])];
    const double* c = &mesh.points[3 * static_cast<std::size_t>(f[2])];
    volume +=
        (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) + a[2] * (b[0] * c[1] - b[1] * c[0])) /
        6.0;
  }
  return volume;
}

// Second value of the line after `section` in an MSH 4.1 file: its total count.
long long declared_count(const std::string& text, const std::string& section) {
  std::istringstream in(text.substr(text.find(section + "\n") + section.size() + 1));
  long long blocks = 0;
  long long count = 0;
  in >> blocks >> count;
  return count;
}

std::string error_of(const std::function<void()>& action) {
  try {
    action();
  } catch (const MeshError& error) {
    return error.what();
  } catch (const std::exception& error) {
    return std::string("<other exception: ") + error.what() + ">";
  }
  return "<no error>";
}

// -------------------------------------------------------------------------------- IPC meshes

class IpcMesh : public ::testing::TestWithParam<const char*> {};

TEST_P(IpcMesh, ReadsCountsOrientationAndClosedBoundary) {
  const std::string path = kDataDir + "/" + GetParam();
  const std::string text = read_all(path);
  ASSERT_FALSE(text.empty()) << path;
  MeshReadReport report;
  const TetMesh mesh = read_tet_mesh(path, &report);
  EXPECT_EQ(mesh.point_count(), declared_count(text, "$Nodes"));
  EXPECT_EQ(mesh.tet_count(), declared_count(text, "$Elements"));
  EXPECT_EQ(report.reoriented_tets, 0);  // PROVENANCE.md: all positively oriented
  EXPECT_EQ(report.unused_points, 0);
  EXPECT_EQ(report.skipped_elements, 0);
  EXPECT_TRUE(report.warnings.empty());
  EXPECT_TRUE(mesh.youngs_modulus.empty());
  double sum = 0.0;
  for (std::size_t t = 0; t < mesh.tetrahedra.size() / 4; ++t) {
    const double v = volume_of(mesh, t);
    EXPECT_GT(v, 0.0) << "tetrahedron " << t;
    sum += v;
  }
  EXPECT_NEAR(tet_mesh_volume(mesh), sum, 1e-12 * std::fabs(sum));
  std::size_t boundary_faces = 0;
  const double enclosed = boundary_volume(mesh, boundary_faces);
  EXPECT_GT(boundary_faces, 0u);
  EXPECT_NEAR(enclosed, sum, 1e-9 * sum);
  if (std::string(GetParam()).rfind("bar-", 0) == 0) {
    EXPECT_NEAR(sum, 10.0 * 0.5 * 1.0, 5e-9);  // a 10 x 0.5 x 1 box
  }
}

INSTANTIATE_TEST_SUITE_P(Files, IpcMesh,
                         ::testing::Values("bar-6.msh", "bar-186.msh", "bar-651.msh", "bar-2523.msh", "cube.msh",
                                           "tet.msh", "sphere1K.msh"),
                         [](const ::testing::TestParamInfo<const char*>& param_info) {
                           std::string name = param_info.param;
                           name = name.substr(0, name.find('.'));
                           std::replace(name.begin(), name.end(), '-', '_');
                           return name;
                         });

TEST(IpcMeshFiles, BarCountsMatchTheName) {
  const std::pair<const char*, int> bars[] = {
      {"bar-6.msh", 6}, {"bar-186.msh", 186}, {"bar-651.msh", 651}, {"bar-2523.msh", 2523}};
  for (const auto& bar : bars) {
    EXPECT_EQ(read_tet_mesh(kDataDir + "/" + bar.first).tet_count(), bar.second) << bar.first;
  }
  EXPECT_EQ(read_tet_mesh(kDataDir + "/bar-6.msh").point_count(), 8);
  EXPECT_EQ(read_tet_mesh(kDataDir + "/sphere1K.msh").point_count(), 1760);
}

TEST(IpcMeshFiles, TetMshNumbersNodesInFileOrder) {
  const TetMesh mesh = read_tet_mesh(kDataDir + "/tet.msh");
  const std::vector<double> points = {0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 1, 0};
  EXPECT_EQ(mesh.points, points);
  EXPECT_EQ(mesh.tetrahedra, (std::vector<int>{0, 3, 2, 1}));  // "1 1 4 3 2"
}

// -------------------------------------------------------------------------------- MSH 4.1 ASCII

// Two tetrahedra sharing a face; node tags sparse and out of order, split over two entity
// blocks, one of them parametric; the second tetrahedron is stored negatively oriented; a point,
// a line and two triangles are skipped, as are $Entities, $PhysicalNames and a user section.
const std::string kSparseMsh =
    "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n"
    "$PhysicalNames\n1\n3 1 \"body\"\n$EndPhysicalNames\n"
    "$Entities\n0 0 0 1\n1 0 0 0 1 1 1 0 0\n$EndEntities\n"
    "$Nodes\n2 5 3 90\n"
    "3 1 0 3\n90\n10\n3\n0 0 0\n1 0 0\n0 1 0\n"
    "2 1 1 2\n7\n55\n0 0 1 0.5 0.5\n1 1 1 0.25 0.75\n"
    "$EndNodes\n"
    "$Elements\n4 6 1 11\n"
    "0 1 15 1\n1 90\n"
    "1 1 1 1\n2 90 10\n"
    "2 1 2 2\n3 90 10 3\n4 10 3 55\n"
    "3 1 4 2\n"
    "10 90 10 3 7\n"
    "11 10 3 55 7\n"
    "$EndElements\n"
    "$Surface\nanything 1 2 3\n$EndSurface\n";

TEST(Msh41, SparseTagsBlocksSkippedElementsAndOrientation) {
  MeshReadReport report;
  const TetMesh mesh = parse_msh(kSparseMsh, "sparse.msh", &report);
  ASSERT_EQ(mesh.point_count(), 5);
  ASSERT_EQ(mesh.tet_count(), 2);
  EXPECT_EQ(mesh.points, (std::vector<double>{0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 1, 1, 1}));
  // Tags 90 10 3 7 55 -> 0 1 2 3 4; the second tetrahedron (1 2 4 3) had its last two swapped.
  EXPECT_EQ(mesh.tetrahedra, (std::vector<int>{0, 1, 2, 3, 1, 2, 3, 4}));
  EXPECT_EQ(report.reoriented_tets, 1);
  EXPECT_EQ(report.skipped_elements, 4);
  EXPECT_EQ(report.unused_points, 0);
  ASSERT_EQ(report.warnings.size(), 1u);
  EXPECT_NE(report.warnings[0].find("sparse.msh: 1 tetrahedra were negatively oriented"), std::string::npos)
      << report.warnings[0];
  for (std::size_t t = 0; t < 2; ++t) EXPECT_GT(volume_of(mesh, t), 0.0);
}

TEST(Msh41, UnusedPointsAreKeptAndReported) {
  const std::string text =
      "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 6 1 6\n3 1 0 6\n1\n2\n3\n4\n5\n6\n"
      "0 0 0\n1 0 0\n0 1 0\n9 9 9\n0 0 1\n8 8 8\n$EndNodes\n"
      "$Elements\n1 1 1 1\n3 1 4 1\n1 1 2 3 5\n$EndElements\n";
  MeshReadReport report;
  const TetMesh mesh = parse_msh(text, "unused.msh", &report);
  EXPECT_EQ(mesh.point_count(), 6);
  EXPECT_EQ(report.unused_points, 2);
  ASSERT_EQ(report.warnings.size(), 1u);
  EXPECT_EQ(report.warnings[0],
            "unused.msh: 2 point(s) are used by no tetrahedron and were kept (first: point 3, "
            "0-based)");
}

TEST(Msh41, CrlfLineEndingsAndBlankLinesInElements) {
  std::string text = kSparseMsh;
  std::string crlf;
  for (const char c : text) {
    if (c == '\n') crlf += '\r';
    crlf += c;
  }
  const TetMesh a = parse_msh(kSparseMsh, "a.msh");
  const TetMesh b = parse_msh(crlf, "b.msh");
  EXPECT_EQ(a.points, b.points);
  EXPECT_EQ(a.tetrahedra, b.tetrahedra);
}

// -------------------------------------------------------------------------------- MSH 4.1 binary

class BinaryWriter {
 public:
  explicit BinaryWriter(bool big_endian) : big_(big_endian) {}
  template <typename T>
  void put(T value) {
    unsigned char bytes[sizeof(T)];
    std::memcpy(bytes, &value, sizeof(T));
    const std::uint16_t probe = 1;
    unsigned char first = 0;
    std::memcpy(&first, &probe, 1);
    const bool host_little = first == 1;
    if (host_little == big_) std::reverse(bytes, bytes + sizeof(T));
    out.append(reinterpret_cast<const char*>(bytes), sizeof(T));
  }
  void text(const std::string& s) { out += s; }
  std::string out;

 private:
  bool big_;
};

// The mesh of kSparseMsh (without the point entity and the sections) in binary MSH 4.1.
std::string binary_msh(bool big_endian) {
  BinaryWriter w(big_endian);
  w.text("$MeshFormat\n4.1 1 8\n");
  w.put<std::int32_t>(1);
  w.text("\n$EndMeshFormat\n$Entities\n");
  // 0 points, 0 curves, 0 surfaces, 1 volume: tag, bounding box, no physicals, no surfaces.
  for (int k = 0; k < 3; ++k) w.put<std::uint64_t>(0);
  w.put<std::uint64_t>(1);
  w.put<std::int32_t>(1);
  for (int k = 0; k < 6; ++k) w.put<double>(k < 3 ? 0.0 : 1.0);
  w.put<std::uint64_t>(0);
  w.put<std::uint64_t>(0);
  w.text("\n$EndEntities\n$Nodes\n");
  w.put<std::uint64_t>(2);
  w.put<std::uint64_t>(5);
  w.put<std::uint64_t>(3);
  w.put<std::uint64_t>(90);
  w.put<std::int32_t>(3);
  w.put<std::int32_t>(1);
  w.put<std::int32_t>(0);
  w.put<std::uint64_t>(3);
  for (const std::uint64_t tag : {90u, 10u, 3u}) w.put<std::uint64_t>(tag);
  for (const double v : {0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0}) w.put<double>(v);
  w.put<std::int32_t>(2);
  w.put<std::int32_t>(1);
  w.put<std::int32_t>(1);
  w.put<std::uint64_t>(2);
  for (const std::uint64_t tag : {7u, 55u}) w.put<std::uint64_t>(tag);
  for (const double v : {0.0, 0.0, 1.0, 0.5, 0.5, 1.0, 1.0, 1.0, 0.25, 0.75}) w.put<double>(v);
  w.text("\n$EndNodes\n$Elements\n");
  w.put<std::uint64_t>(2);
  w.put<std::uint64_t>(4);
  w.put<std::uint64_t>(1);
  w.put<std::uint64_t>(4);
  w.put<std::int32_t>(2);
  w.put<std::int32_t>(1);
  w.put<std::int32_t>(2);
  w.put<std::uint64_t>(2);
  for (const std::uint64_t v : {1u, 90u, 10u, 3u, 2u, 10u, 3u, 55u}) w.put<std::uint64_t>(v);
  w.put<std::int32_t>(3);
  w.put<std::int32_t>(1);
  w.put<std::int32_t>(4);
  w.put<std::uint64_t>(2);
  for (const std::uint64_t v : {3u, 90u, 10u, 3u, 7u, 4u, 10u, 3u, 55u, 7u}) w.put<std::uint64_t>(v);
  w.text("\n$EndElements\n");
  return w.out;
}

TEST(Msh41Binary, LittleAndBigEndianMatchAscii) {
  const TetMesh ascii = parse_msh(kSparseMsh, "ascii.msh");
  for (const bool big : {false, true}) {
    MeshReadReport report;
    const TetMesh mesh = parse_msh(binary_msh(big), "binary.msh", &report);
    EXPECT_EQ(mesh.points, ascii.points) << (big ? "big" : "little");
    EXPECT_EQ(mesh.tetrahedra, ascii.tetrahedra);
    EXPECT_EQ(report.reoriented_tets, 1);
    EXPECT_EQ(report.skipped_elements, 2);
  }
}

TEST(Msh41Binary, EveryTruncationIsAOneLineError) {
  const std::string full = binary_msh(false);
  // Every prefix short of the final "$EndElements" fails; that and the full file read.
  for (std::size_t size = 0; size + 1 < full.size(); ++size) {
    const std::string message = error_of([&] { parse_msh(full.substr(0, size), "cut.msh"); });
    EXPECT_EQ(message.rfind("cut.msh", 0), 0u) << size << ": " << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << size << ": " << message;
  }
}

// -------------------------------------------------------------------------------- MSH 2.2

TEST(Msh22, ReadsTaggedElementsAndSkipsSurfaces) {
  const std::string text =
      "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n"
      "$Nodes\n5\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n9 1 1 1\n$EndNodes\n"
      "$Elements\n4\n"
      "1 15 2 0 1 1\n"
      "2 2 2 0 1 1 2 3\n"
      "3 4 2 7 1 1 2 3 4\n"
      "4 4 3 7 1 0 2 9 4 3\n"
      "$EndElements\n";
  MeshReadReport report;
  const TetMesh mesh = parse_msh(text, "v2.msh", &report);
  EXPECT_EQ(mesh.point_count(), 5);
  EXPECT_EQ(mesh.tetrahedra, (std::vector<int>{0, 1, 2, 3, 1, 4, 2, 3}));
  EXPECT_EQ(report.skipped_elements, 2);
  EXPECT_EQ(report.reoriented_tets, 1);
}

// -------------------------------------------------------------------------------- writers

TEST(MshWriter, RoundTripIsExact) {
  TetMesh mesh = read_tet_mesh(kDataDir + "/bar-186.msh");
  mesh.points[0] = 0.1;  // not a short decimal
  mesh.points[5] = -1.0 / 3.0;
  std::ostringstream out;
  write_msh(mesh, out);
  const TetMesh back = parse_msh(out.str(), "written.msh");
  EXPECT_EQ(back.points, mesh.points);
  EXPECT_EQ(back.tetrahedra, mesh.tetrahedra);
}

TEST(TetGenWriter, RoundTripThroughFilesFromEitherSibling) {
  test_support::TempDir dir("pliant_fem_mesh_");
  TetMesh mesh = read_tet_mesh(kDataDir + "/sphere1K.msh");
  for (const int first : {0, 1}) {
    const std::string stem = dir / ("sphere" + std::to_string(first));
    {
      std::ofstream node(stem + ".node");
      std::ofstream ele(stem + ".ele");
      write_tetgen(mesh, node, ele, first);
    }
    for (const char* extension : {".node", ".ele"}) {
      MeshReadReport report;
      const TetMesh back = read_tet_mesh(stem + extension, &report);
      EXPECT_EQ(back.points, mesh.points) << first << extension;
      EXPECT_EQ(back.tetrahedra, mesh.tetrahedra) << first << extension;
      EXPECT_EQ(report.reoriented_tets, 0);
    }
  }
}

TEST(TetGen, CommentsAttributesMarkersAndZeroBase) {
  const std::string node =
      "# a comment line\n"
      "\n"
      "5 3 2 1   # count dim attributes markers\n"
      "0  0 0 0  7.5 1  1\n"
      "1  1 0 0  7.5 1  1 # trailing comment\n"
      "2  0 1 0  7.5 1  0\n"
      "3  0 0 1  7.5 1  1\n"
      "4  5 5 5  0 0  0\n";
  const std::string ele =
      "# tets\n"
      "2 4 1\n"
      "0 0 1 2 3 1\n"
      "1 0 2 1 3 2\n";
  TetGenNodes nodes = parse_tetgen_node(node, "m.node");
  EXPECT_EQ(nodes.first_index, 0);
  MeshReadReport report;
  const TetMesh mesh = parse_tetgen_ele(ele, "m.ele", std::move(nodes), &report);
  EXPECT_EQ(mesh.point_count(), 5);
  EXPECT_EQ(mesh.tetrahedra, (std::vector<int>{0, 1, 2, 3, 0, 2, 3, 1}));
  EXPECT_EQ(report.reoriented_tets, 1);
  EXPECT_EQ(report.unused_points, 1);
  EXPECT_EQ(report.warnings.size(), 2u);
}

TEST(TetGen, OneBasedHeaderWithoutOptionalFields) {
  TetGenNodes nodes = parse_tetgen_node("4\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n", "m.node");
  EXPECT_EQ(nodes.first_index, 1);
  const TetMesh mesh = parse_tetgen_ele("1\n1 1 2 3 4\n", "m.ele", std::move(nodes));
  EXPECT_EQ(mesh.tetrahedra, (std::vector<int>{0, 1, 2, 3}));
}

TEST(TetGen, FilesWithoutFinalNewline) {
  TetGenNodes nodes = parse_tetgen_node("1\n1 0 0 0", "one.node");
  EXPECT_EQ(nodes.points.size(), 3u);
  nodes = parse_tetgen_node("4\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1", "m.node");
  const TetMesh mesh = parse_tetgen_ele("1\n1 1 2 3 4", "m.ele", std::move(nodes));
  EXPECT_EQ(mesh.tet_count(), 1);
}

// -------------------------------------------------------------------------------- VTK

TEST(ReadTetMesh, VtkIsOrientedAndKeepsYoungsModulus) {
  test_support::TempDir dir("pliant_fem_mesh_");
  TetMesh mesh;
  mesh.points = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
  mesh.tetrahedra = {0, 2, 1, 3};  // negative
  mesh.youngs_modulus = {5e4};
  {
    std::ofstream out(dir / "neg.vtk");
    write_vtk_tet_mesh(mesh, out);
  }
  MeshReadReport report;
  const TetMesh back = read_tet_mesh(dir / "neg.vtk", &report);
  EXPECT_EQ(back.tetrahedra, (std::vector<int>{0, 2, 3, 1}));
  EXPECT_EQ(back.youngs_modulus, mesh.youngs_modulus);
  EXPECT_EQ(report.reoriented_tets, 1);
  EXPECT_GT(tet_mesh_volume(back), 0.0);
}

TEST(ReadTetMesh, VtkParseErrorsBecomeMeshError) {
  test_support::TempDir dir("pliant_fem_mesh_");
  write_all(dir / "bad.vtk", "# vtk DataFile Version 3.0\nx\nBINARY\n");
  const std::string message = error_of([&] { read_tet_mesh(dir / "bad.vtk"); });
  EXPECT_NE(message.find("bad.vtk:3: binary VTK files are not supported"), std::string::npos) << message;
}

TEST(ReadTetMesh, UppercaseExtensions) {
  test_support::TempDir dir("pliant_fem_mesh_");
  write_all(dir / "T.MSH", read_all(kDataDir + "/tet.msh"));
  EXPECT_EQ(read_tet_mesh(dir / "T.MSH").tet_count(), 1);
}

TEST(OrientAndCheck, FixesInMemoryMeshes) {
  TetMesh mesh;
  mesh.points = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
  mesh.tetrahedra = {1, 0, 2, 3};
  MeshReadReport report;
  orient_and_check_tet_mesh(mesh, "memory", &report);
  EXPECT_EQ(mesh.tetrahedra, (std::vector<int>{1, 0, 3, 2}));
  EXPECT_EQ(report.reoriented_tets, 1);
  EXPECT_NEAR(tet_mesh_volume(mesh), 1.0 / 6.0, 1e-15);
  mesh.tetrahedra = {0, 1, 2, 4};
  EXPECT_EQ(error_of([&] { orient_and_check_tet_mesh(mesh, "memory"); }),
            "memory: tetrahedron 0: point index 4 out of range (the mesh has 4 points)");
}

}  // namespace
}  // namespace pliant::host
