// Malformed mesh and surface files, one cause each: every parser must throw MeshError with one
// line naming the file and the line (or byte offset) and the cause, and nothing else.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <fstream>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include "../support/temp_dir.hpp"
#include "pliant/host/fem/mesh_io.hpp"
#include "pliant/host/fem/surface_io.hpp"

namespace pliant::host {
namespace {

// Lines: 1-3 format, 4 $Nodes, 5 header, 6 block, 7-10 tags, 11-14 coordinates, 15 $EndNodes,
// 16 $Elements, 17 header, 18 block, 19 tetrahedron, 20 $EndElements.
const std::string kMsh =
    "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n"
    "$Nodes\n1 4 1 4\n3 1 0 4\n1\n2\n3\n4\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n$EndNodes\n"
    "$Elements\n1 1 1 1\n3 1 4 1\n1 1 2 3 4\n$EndElements\n";

const std::string kNode = "4 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n";
const std::string kEle = "1 4 0\n1 1 2 3 4\n";

const std::string kObjTriangle = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";

const std::string kPlyAsciiHeader =
    "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
    "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";

const std::string kCubeObj =
    "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n"
    "f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n";

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const std::size_t at = text.find(from);
  if (at == std::string::npos) throw std::logic_error("test text lacks '" + from + "'");
  return text.replace(at, from.size(), to);
}

// kMsh with the first two points written out as gmsh does, so that a cut after them still
// leaves enough bytes for the node count to be plausible.
std::string long_coordinates() {
  return replaced(kMsh, "0 0 0\n1 0 0\n",
                  "0.000000e+00 0.000000e+00 0.000000e+00\n1.000000e+00 0.000000e+00 "
                  "0.000000e+00\n");
}

std::string truncated_before(const std::string& text, const std::string& marker) {
  return text.substr(0, text.find(marker));
}

std::string binary_ply_truncated() {
  std::string text =
      "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n"
      "property float y\nproperty float z\nelement face 1\n"
      "property list uchar int vertex_indices\nend_header\n";
  const float coordinates[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  for (const float value : coordinates) {
    char bytes[4];
    std::memcpy(bytes, &value, 4);
    text.append(bytes, 4);
  }
  text.push_back('\3');
  const std::int32_t first = 0;
  char bytes[4];
  std::memcpy(bytes, &first, 4);
  text.append(bytes, 4);  // one of three indices, then the file ends
  return text;
}

std::string binary_stl_wrong_size() {
  std::string text(80, ' ');
  const std::uint32_t count = 5;
  char bytes[4];
  std::memcpy(bytes, &count, 4);
  text.append(bytes, 4);
  text.append(60, '\0');
  return text;
}

struct Case {
  const char* name;
  std::function<void()> action;
  std::string prefix;  ///< the message starts with this (file and line or byte)
  std::string cause;   ///< and contains this
};

TetGenNodes valid_nodes() { return parse_tetgen_node(kNode, "x.node"); }

std::vector<Case> cases() {
  auto msh = [](std::string text) { return [text] { parse_msh(text, "x.msh"); }; };
  auto node = [](std::string text) { return [text] { parse_tetgen_node(text, "x.node"); }; };
  auto ele = [](std::string text) { return [text] { parse_tetgen_ele(text, "x.ele", valid_nodes()); }; };
  auto obj = [](std::string text) { return [text] { parse_obj(text, "x.obj"); }; };
  auto ply = [](std::string text) { return [text] { parse_ply(text, "x.ply"); }; };
  auto stl = [](std::string text) { return [text] { parse_stl(text, "x.stl"); }; };
  return {
      // ---------------------------------------------------------------- gmsh MSH
      {"MshNotGmsh", msh("hello\n"), "x.msh:1: ", "not a gmsh MSH file"},
      {"MshVersion3", msh(replaced(kMsh, "4.1 0 8", "3.0 0 8")), "x.msh:2: ", "unsupported MSH version 3.0"},
      {"MshVersion40", msh(replaced(kMsh, "4.1 0 8", "4.0 0 8")), "x.msh:2: ", "unsupported MSH version 4.0"},
      {"MshBadFileType", msh(replaced(kMsh, "4.1 0 8", "4.1 2 8")),
       "x.msh:2: ", "file type must be 0 (ASCII) or 1 (binary)"},
      {"MshTruncatedNodes", msh(truncated_before(long_coordinates(), "0 1 0\n")),
       "x.msh:13: ", "unexpected end of file, expected a coordinate of node 3"},
      {"MshMissingEndNodes", msh(replaced(kMsh, "$EndNodes\n", "")),
       "x.msh:15: ", "expected $EndNodes, found '$Elements'"},
      {"MshNodeCountMismatch", msh(replaced(kMsh, "1 4 1 4\n", "1 5 1 4\n")),
       "x.msh:14: ", "declares 5 nodes but its blocks hold 4"},
      {"MshNegativeCount", msh(replaced(kMsh, "3 1 0 4\n", "3 1 0 -4\n")),
       "x.msh:6: ", "node count of node block 0 must not be negative"},
      {"MshHugeCount", msh(replaced(kMsh, "1 4 1 4\n", "1 1000000000000000 1 4\n")), "x.msh:5: ", "exceeds the limit"},
      {"MshCountLargerThanFile", msh(replaced(kMsh, "1 4 1 4\n", "1 50000000 1 4\n")),
       "x.msh:5: ", "is larger than the rest of the file can hold"},
      {"MshNanCoordinate", msh(replaced(kMsh, "0 1 0\n", "0 nan 0\n")), "x.msh:13: ", "is not finite"},
      {"MshUndefinedNode", msh(replaced(kMsh, "1 1 2 3 4\n", "1 1 2 3 9\n")),
       "x.msh:19: ", "node tag 9 is not defined in $Nodes"},
      {"MshDegenerateTet", msh(replaced(kMsh, "0 0 1\n$End", "1 1 0\n$End")),
       "x.msh:19: ", "tetrahedron 0 has zero volume (degenerate"},
      {"MshRepeatedNode", msh(replaced(kMsh, "1 1 2 3 4\n", "1 1 2 3 3\n")), "x.msh:19: ", "repeats a point"},
      {"MshSecondOrderTet", msh(replaced(kMsh, "3 1 4 1\n1 1 2 3 4\n", "3 1 11 1\n1 1 2 3 4 1 2 3 4 1 2\n")),
       "x.msh:18: ", "element type 11 (10-node second-order tetrahedron) is not supported"},
      {"MshHexahedron", msh(replaced(kMsh, "3 1 4 1\n", "3 1 5 1\n")),
       "x.msh:18: ", "element type 5 (8-node hexahedron) is not supported"},
      {"MshElementsBeforeNodes", msh("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Elements\n0 0 0 0\n$EndElements\n"),
       "x.msh:4: ", "$Elements before $Nodes"},
      {"MshDuplicateNodeTag", msh(replaced(kMsh, "3\n4\n0 0 0", "3\n3\n0 0 0")),
       "x.msh:4: ", "node tag 3 is defined twice"},
      {"MshUnterminatedSection", msh(kMsh + "$Surface\n1 2 3\n"),
       "x.msh:21: ", "missing $EndSurface (section $Surface opened at line 21)"},
      {"MshOnlyTriangles", msh(replaced(kMsh, "3 1 4 1\n1 1 2 3 4\n", "2 1 2 1\n1 1 2 3\n")),
       "x.msh:", "no 4-node tetrahedra (type 4) in $Elements (only points, lines or surface elements)"},
      {"MshShortElementLine", msh(replaced(kMsh, "1 1 2 3 4\n", "1 1 2 3\n")),
       "x.msh:19: ", "needs an element tag and 4 node tags, found 4 values"},
      {"MshElementCountMismatch", msh(replaced(kMsh, "1 1 1 1\n", "1 2 1 1\n")),
       "x.msh:", "declares 2 elements but its blocks hold 1"},
      {"MshStrayEnd", msh(replaced(kMsh, "$Nodes\n", "$EndNodes\n")),
       "x.msh:4: ", "'$EndNodes' without its opening section"},
      {"MshBinaryTruncatedHeader", msh("$MeshFormat\n4.1 1 8\n"), "x.msh:3: ", "unexpected end of file in header"},
      {"MshBinaryDataSize", msh("$MeshFormat\n4.1 1 2\n"), "x.msh:2: ", "data size (size of size_t) must be 4 or 8"},
      // ---------------------------------------------------------------- TetGen
      {"NodeOutOfSequence", node(replaced(kNode, "3 0 1 0", "7 0 1 0")),
       "x.node:4: ", "point number 7 out of sequence (expected 3)"},
      {"NodeFirstIndex", node(replaced(kNode, "1 0 0 0", "5 0 0 0")),
       "x.node:2: ", "the first point must be numbered 0 or 1"},
      {"NodeDimension2", node(replaced(kNode, "4 3 0 0", "4 2 0 0")), "x.node:1: ", "dimension 2 is not supported"},
      {"NodeTruncated", node("4\n1 0 0 0\n2 1 0 0\n# padding padding padding\n"),
       "x.node:5: ", "unexpected end of file after 2 of 4 points"},
      {"NodeHugeCount", node("99999999999 3 0 0\n"), "x.node:1: ", "the point count 99999999999 exceeds the limit"},
      {"NodeCountLargerThanFile", node("9999999 3 0 0\n1 0 0 0\n"),
       "x.node:1: ", "is larger than the rest of the file can hold"},
      {"NodeNan", node(replaced(kNode, "2 1 0 0", "2 nan 0 0")), "x.node:3: ", "point 2 has a non-finite coordinate"},
      {"NodeMissingAttribute", node("1 3 1 0\n1 0 0 0\n"),
       "x.node:2: ", "point line has 4 values, the header asks for 5"},
      {"NodeNegativeCount", node("-4 3 0 0\n"), "x.node:1: ", "must not be negative"},
      {"EleIndexOutOfRange", ele(replaced(kEle, "1 1 2 3 4", "1 1 2 3 5")),
       "x.ele:2: ", "tetrahedron 0: point 5 out of range 1..4"},
      {"EleSecondOrder", ele("1 10 0\n1 1 2 3 4 1 2 3 4 1 2\n"),
       "x.ele:1: ", "second-order tetrahedra (10 nodes, tetgen -o2) are not supported"},
      {"EleTrailingData", ele(kEle + "2 1 2 3 4\n"), "x.ele:3: ", "unexpected data after the 1 tetrahedra"},
      {"EleRepeatedPoint", ele(replaced(kEle, "1 1 2 3 4", "1 1 2 3 3")), "x.ele:2: ", "repeats a point"},
      {"EleNotAnInteger", ele(replaced(kEle, "1 1 2 3 4", "1 1 2 3 x")),
       "x.ele:2: ", "expected an integer for a point of tetrahedron 0, found 'x'"},
      {"EleNoTetrahedra", ele("0 4 0\n"), "x.ele: ", "the mesh has no tetrahedra"},
      // ---------------------------------------------------------------- OBJ
      {"ObjIndexOutOfRange", obj(kObjTriangle + "f 1 2 4\n"), "x.obj:4: ", "vertex reference 4 out of range"},
      {"ObjNegativeIndexOutOfRange", obj(kObjTriangle + "f -1 -2 -4\n"),
       "x.obj:4: ", "vertex reference -4 out of range"},
      {"ObjTwoVertexFace", obj(kObjTriangle + "f 1 2\n"), "x.obj:4: ", "a face needs at least 3 vertices, found 2"},
      {"ObjRepeatedVertex", obj(kObjTriangle + "f 1 2 1\n"), "x.obj:4: ", "a face repeats vertex 0"},
      {"ObjNan", obj("v nan 0 0\n" + kObjTriangle + "f 2 3 4\n"), "x.obj:1: ", "a vertex has a non-finite coordinate"},
      {"ObjFreeForm", obj(kObjTriangle + "curv 0 1 1 2\n"), "x.obj:4: ", "unsupported OBJ statement 'curv'"},
      {"ObjNoFaces", obj(kObjTriangle), "x.obj: ", "no faces"},
      // ---------------------------------------------------------------- PLY
      {"PlyNotPly", ply("plx\n"), "x.ply:1: ", "not a PLY file"},
      {"PlyMissingEndHeader", ply("ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"),
       "x.ply:5: ", "no end_header line"},
      {"PlyUnknownFormat", ply(replaced(kPlyAsciiHeader, "ascii", "binary_middle_endian")),
       "x.ply:2: ", "unknown PLY format 'binary_middle_endian'"},
      {"PlyBinaryTruncated", ply(binary_ply_truncated()), "x.ply: byte ",
       "list length 3 is larger than the rest of the file can hold"},
      {"PlyFaceIndexOutOfRange", ply(kPlyAsciiHeader + "0 0 0\n1 0 0\n0 1 0\n3 0 1 5\n"),
       "x.ply:13: ", "face 0 (of 1): vertex index 5 out of range"},
      {"PlyHugeCount", ply(replaced(kPlyAsciiHeader, "vertex 3", "vertex 999999999999")),
       "x.ply:3: ", "vertex count 999999999999 exceeds the limit"},
      {"PlyCountLargerThanFile", ply(replaced(kPlyAsciiHeader, "vertex 3", "vertex 9999999")),
       "x.ply:3: ", "is larger than the rest of the file can hold"},
      {"PlyNoZ", ply(replaced(kPlyAsciiHeader, "property float z\n", "")),
       "x.ply:3: ", "the vertex element has no property z"},
      {"PlyAsciiBadNumber", ply(kPlyAsciiHeader + "0 0 0\n1 zero 0\n0 1 0\n3 0 1 2\n"),
       "x.ply:11: ", "expected a number in vertex 1 (of 3), found 'zero'"},
      // ---------------------------------------------------------------- STL
      {"StlFourVertices",
       stl("solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n"
           "vertex 1 1 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid s\n"),
       "x.stl:7: ", "a facet has more than 3 vertices"},
      {"StlMissingEndsolid",
       stl("solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n"
           "vertex 1 1 0\nendloop\nendfacet\n"),
       "x.stl:9: ", "unexpected end of file, missing 'endsolid'"},
      {"StlBinarySizeMismatch", stl(binary_stl_wrong_size()), "x.stl: ",
       "binary STL size mismatch: the header declares 5 triangles (334 bytes), the file has 144 "
       "bytes"},
      {"StlNotStl", stl("hello"), "x.stl: ", "not an STL file"},
      // ---------------------------------------------------------------- closedness and files
      {"SurfaceNotClosed",
       [] {
         TriangleSurface surface = parse_obj(replaced(kCubeObj, "f 4 1 5 8\n", "f 4 1 5\n"), "x.obj");
         merge_duplicate_vertices(surface, "x.obj");
         require_closed_surface(surface, "x.obj");
       },
       "x.obj: ", "surface is not closed: 3 boundary edge(s) (used by one triangle)"},
      {"SurfaceNonManifold",
       [] {
         TriangleSurface surface = parse_obj(kCubeObj + "f 1 2 7\n", "x.obj");
         require_closed_surface(surface, "x.obj");
       },
       "x.obj: ", "non-manifold"},
      {"MissingFile", [] { read_tet_mesh("/nonexistent/dir/x.msh"); }, "/nonexistent/dir/x.msh: ", "no such file"},
      {"UnknownExtension", [] { read_tet_mesh("/tmp/x.off"); }, "/tmp/x.off: ", "unknown mesh extension '.off'"},
  };
}

class Malformed : public ::testing::TestWithParam<Case> {};

TEST_P(Malformed, GivesOneLineErrorNamingFileAndCause) {
  const Case& c = GetParam();
  std::string message = "<no error>";
  try {
    c.action();
  } catch (const MeshError& error) {
    message = error.what();
  } catch (const std::exception& error) {
    message = std::string("<other exception: ") + error.what() + ">";
  }
  EXPECT_EQ(message.rfind(c.prefix, 0), 0u) << "message: " << message << "\nexpected prefix: " << c.prefix;
  EXPECT_NE(message.find(c.cause), std::string::npos) << "message: " << message << "\nexpected cause: " << c.cause;
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
}

INSTANTIATE_TEST_SUITE_P(Files, Malformed, ::testing::ValuesIn(cases()),
                         [](const ::testing::TestParamInfo<Case>& param_info) {
                           return std::string(param_info.param.name);
                         });

TEST(MalformedFiles, EleWithoutNodeSibling) {
  test_support::TempDir dir("pliant_fem_mesh_");
  {
    std::ofstream out(dir / "lonely.ele");
    out << kEle;
  }
  std::string message;
  try {
    read_tet_mesh(dir / "lonely.ele");
  } catch (const MeshError& error) {
    message = error.what();
  }
  EXPECT_EQ(message, (dir / "lonely.node") + ": no such file");
}

TEST(MalformedFiles, EveryPrefixOfAValidMeshFailsCleanlyOrSucceeds) {
  for (std::size_t size = 0; size <= kMsh.size(); ++size) {
    try {
      parse_msh(kMsh.substr(0, size), "cut.msh");
    } catch (const MeshError& error) {
      EXPECT_EQ(std::string(error.what()).find('\n'), std::string::npos);
    }
  }
  const std::string ply = kPlyAsciiHeader + "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
  for (std::size_t size = 0; size <= ply.size(); ++size) {
    try {
      parse_ply(ply.substr(0, size), "cut.ply");
    } catch (const MeshError& error) {
      EXPECT_EQ(std::string(error.what()).find('\n'), std::string::npos);
    }
  }
}

}  // namespace
}  // namespace pliant::host
