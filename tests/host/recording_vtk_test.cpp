// mesh.vtk: malformed legacy VTK files (one cause each), both cell layouts, and the writer.
#include <cstring>
#include <sstream>
#include <stdexcept>
#include <string>

#include "pliant/host/recording.hpp"
#include "pliant/host/vtk_mesh.hpp"
#include "recording_test_support.hpp"

namespace pliant::host::test {
namespace {

// Lines: 5 POINTS, 6-10 points, 11 CELLS, 12-13 cells, 14 CELL_TYPES, 15-16 types,
// 17 CELL_DATA, 18 SCALARS, 19 LOOKUP_TABLE, 20-21 values.
const std::string kClassic =
    "# vtk DataFile Version 3.0\n"
    "two tetrahedra\n"
    "ASCII\n"
    "DATASET UNSTRUCTURED_GRID\n"
    "POINTS 5 double\n"
    "0 0 0\n1 0 0\n0 1 0\n0 0 1\n1 1 1\n"
    "CELLS 2 10\n"
    "4 0 1 2 3\n4 1 2 3 4\n"
    "CELL_TYPES 2\n"
    "10\n10\n"
    "CELL_DATA 2\n"
    "SCALARS youngs_modulus double 1\n"
    "LOOKUP_TABLE default\n"
    "50000\n70000\n";

// Version 5.1 layout as written by VTK 9 and meshio, with a METADATA block after POINTS.
// Lines: 5 POINTS, 6 points, 7 METADATA, 8 INFORMATION, 9 NAME, 10 DATA, 11 blank, 12 CELLS,
// 13 OFFSETS, 14 offsets, 15 CONNECTIVITY, 16 connectivity, 17 CELL_TYPES, 18 types.
const std::string kOffsets =
    "# vtk DataFile Version 5.1\n"
    "vtk output\n"
    "ASCII\n"
    "DATASET UNSTRUCTURED_GRID\n"
    "POINTS 5 float\n"
    "0 0 0 1 0 0 0 1 0 0 0 1 1 1 1\n"
    "METADATA\n"
    "INFORMATION 1\n"
    "NAME L2_NORM_RANGE LOCATION vtkDataArray\n"
    "DATA 2 0 1.73205\n"
    "\n"
    "CELLS 3 8\n"
    "OFFSETS vtktypeint64\n"
    "0 4 8\n"
    "CONNECTIVITY vtktypeint64\n"
    "0 1 2 3 1 2 3 4\n"
    "CELL_TYPES 2\n"
    "10 10\n";

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const std::size_t at = text.find(from);
  if (at == std::string::npos) throw std::logic_error("test text lacks '" + from + "'");
  return text.replace(at, from.size(), to);
}

struct VtkCase {
  const char* name;
  std::string text;
  const char* prefix;
  const char* cause;
};

void PrintTo(const VtkCase& c, std::ostream* out) { *out << c.name; }

class VtkMalformed : public ::testing::TestWithParam<VtkCase> {};

TEST_P(VtkMalformed, NamesFileLineAndCause) {
  const std::string message = error_of([&] { parse_vtk_tet_mesh(GetParam().text, "mesh.vtk"); });
  expect_message(message, GetParam().prefix, GetParam().cause);
}

INSTANTIATE_TEST_SUITE_P(
    Mesh, VtkMalformed,
    ::testing::Values(
        VtkCase{"NotVtk", "solid cube\nfacet normal 0 0 1\n", "mesh.vtk:1: ", "not a legacy VTK file"},
        VtkCase{"Binary", replaced(kClassic, "ASCII", "BINARY"), "mesh.vtk:3: ", "binary VTK files are not supported"},
        VtkCase{"PolyData", replaced(kClassic, "UNSTRUCTURED_GRID", "POLYDATA"),
                "mesh.vtk:4: ", "dataset type 'POLYDATA' is not supported"},
        VtkCase{"HexahedronCell", replaced(kClassic, "CELLS 2 10\n4 0 1 2 3\n", "CELLS 2 14\n8 0 1 2 3 4 0 1 2\n"),
                "mesh.vtk:12: ", "cell 0 has 8 points, only tetrahedra (4 points) are supported"},
        VtkCase{"HexahedronType", replaced(kClassic, "10\n10\n", "10\n12\n"),
                "mesh.vtk:16: ", "cell 1 has type 12, only tetrahedra (type 10) are supported"},
        VtkCase{"IndexOutOfRange", replaced(kClassic, "4 1 2 3 4", "4 1 2 3 5"),
                "mesh.vtk:13: ", "cell 1: point index 5 out of range 0..4"},
        VtkCase{"RepeatedPoint", replaced(kClassic, "4 1 2 3 4", "4 1 2 1 4"),
                "mesh.vtk:13: ", "cell 1 repeats point 1"},
        VtkCase{"PointsCountTooLarge", replaced(kClassic, "POINTS 5", "POINTS 6"),
                "mesh.vtk:11: ", "expected a number for point 5 of 6, found 'CELLS'"},
        VtkCase{"PointsCountTooSmall", replaced(kClassic, "POINTS 5", "POINTS 4"),
                "mesh.vtk:10: ", "unexpected '1' where a section keyword belongs"},
        VtkCase{"CellsSizeMismatch", replaced(kClassic, "CELLS 2 10", "CELLS 2 11"),
                "mesh.vtk:11: ", "CELLS size 11 does not match the 10 values of its 2 cells"},
        VtkCase{"CellTypesCountMismatch", replaced(kClassic, "CELL_TYPES 2", "CELL_TYPES 3"),
                "mesh.vtk:14: ", "CELL_TYPES count 3 does not match the 2 cells"},
        VtkCase{"CellTypesMissing", replaced(kClassic, "CELL_TYPES 2\n10\n10\nCELL_DATA", "CELL_DATA"),
                "mesh.vtk:14: ", "CELL_DATA before CELLS and CELL_TYPES"},
        VtkCase{"NoCellTypesAtAll", replaced(kOffsets, "CELL_TYPES 2\n10 10\n", ""),
                "mesh.vtk:16: ", "no CELL_TYPES section"},
        VtkCase{"CellDataCountMismatch", replaced(kClassic, "CELL_DATA 2", "CELL_DATA 5"),
                "mesh.vtk:17: ", "CELL_DATA count 5 does not match the 2 cells"},
        VtkCase{"YoungsModulusNotPositive", replaced(kClassic, "70000", "-1"),
                "mesh.vtk:21: ", "youngs_modulus of cell 1 must be positive and finite"},
        VtkCase{"NamedLookupTable", replaced(kClassic, "LOOKUP_TABLE default", "LOOKUP_TABLE my"),
                "mesh.vtk:19: ", "only 'LOOKUP_TABLE default' is supported"},
        VtkCase{"FieldSection", replaced(kClassic, "CELL_DATA 2\n", "FIELD FieldData 1\n"),
                "mesh.vtk:17: ", "unsupported section 'FIELD'"},
        VtkCase{"PointNotFinite", replaced(kClassic, "1 1 1\n", "1 nan 1\n"),
                "mesh.vtk:10: ", "point 4 has a non-finite coordinate"},
        VtkCase{"TruncatedPoints", kClassic.substr(0, kClassic.find("0 0 1\n")),
                "mesh.vtk:8: ", "unexpected end of file, expected point 3 of 5"},
        VtkCase{"OffsetsNotTetrahedra", replaced(kOffsets, "0 4 8\n", "0 4 7\n"),
                "mesh.vtk:14: ", "cell 1 has 3 points, only tetrahedra"},
        VtkCase{"OffsetsDecrease", replaced(kOffsets, "0 4 8\n", "0 4 -9223372036854775808\n"),
                "mesh.vtk:14: ", "OFFSETS must not decrease"},
        VtkCase{"OffsetsLastMismatch", replaced(kOffsets, "CELLS 3 8", "CELLS 3 9"),
                "mesh.vtk:12: ", "CELLS connectivity size 9 does not match the last offset 8"},
        VtkCase{"ConnectivityOutOfRange", replaced(kOffsets, "1 2 3 4\n", "1 2 3 9\n"),
                "mesh.vtk:16: ", "cell 1: point index 9 out of range 0..4"},
        VtkCase{"HugeCount", replaced(kClassic, "POINTS 5", "POINTS 99999999999999999999"),
                "mesh.vtk:5: ", "is larger than the file can hold"}),
    CaseName());

TEST(VtkMesh, ReadsClassicLayoutWithYoungsModulus) {
  const TetMesh mesh = parse_vtk_tet_mesh(kClassic, "mesh.vtk");
  EXPECT_EQ(mesh.point_count(), 5);
  EXPECT_EQ(mesh.tet_count(), 2);
  EXPECT_EQ(mesh.tetrahedra, (std::vector<int>{0, 1, 2, 3, 1, 2, 3, 4}));
  EXPECT_EQ(mesh.points[3 * 4 + 2], 1.0);
  EXPECT_EQ(mesh.youngs_modulus, (std::vector<double>{50000.0, 70000.0}));
}

TEST(VtkMesh, ReadsOffsetsLayoutAndSkipsMetadata) {
  const TetMesh mesh = parse_vtk_tet_mesh(kOffsets, "mesh.vtk");
  EXPECT_EQ(mesh.point_count(), 5);
  EXPECT_EQ(mesh.tetrahedra, (std::vector<int>{0, 1, 2, 3, 1, 2, 3, 4}));
  EXPECT_TRUE(mesh.youngs_modulus.empty());
}

TEST(VtkMesh, SkipsOtherScalarArraysAndCrlf) {
  std::string text = replaced(kClassic, "CELL_DATA 2\n",
                              "POINT_DATA 5\nSCALARS temperature float\nLOOKUP_TABLE default\n"
                              "1 2 3 4 5\nCELL_DATA 2\nSCALARS region int 1\n"
                              "LOOKUP_TABLE default\n7 8\n");
  std::string crlf;
  for (const char c : text) crlf += c == '\n' ? std::string("\r\n") : std::string(1, c);
  const TetMesh mesh = parse_vtk_tet_mesh(crlf, "mesh.vtk");
  EXPECT_EQ(mesh.youngs_modulus, (std::vector<double>{50000.0, 70000.0}));
}

TEST(VtkMesh, WriterOutputReadsBackExactly) {
  TetMesh mesh;
  mesh.points = {0.1, 0.2, 0.3, 1.0 / 3.0, -0.0, 5e-324, 1e300, 2.0, 3.0, 4.0, 5.0, 6.0};
  mesh.tetrahedra = {3, 2, 1, 0};
  mesh.youngs_modulus = {12345.678901234567};
  std::ostringstream out;
  write_vtk_tet_mesh(mesh, out);
  const TetMesh back = parse_vtk_tet_mesh(out.str(), "mesh.vtk");
  ASSERT_EQ(back.points.size(), mesh.points.size());
  for (std::size_t i = 0; i < mesh.points.size(); ++i) {
    EXPECT_EQ(std::memcmp(&back.points[i], &mesh.points[i], sizeof(double)), 0) << i;
  }
  EXPECT_EQ(back.tetrahedra, mesh.tetrahedra);
  EXPECT_EQ(back.youngs_modulus, mesh.youngs_modulus);
}

TEST(VtkMesh, WriterRejectsInconsistentMesh) {
  TetMesh mesh;
  mesh.points = {0, 0, 0};
  mesh.tetrahedra = {0, 0, 0, 1};
  std::ostringstream out;
  EXPECT_THROW(write_vtk_tet_mesh(mesh, out), std::runtime_error);
}

}  // namespace
}  // namespace pliant::host::test
