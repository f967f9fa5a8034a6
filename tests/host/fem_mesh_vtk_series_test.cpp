// VTK time series: .vtu frames listed in a .pvd (checked with a small XML reader written here),
// legacy .vtk frames read back with parse_vtk_tet_mesh and listed in a .vtk.series JSON file;
// numbers exact; invalid frames refused without changing the series.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <cctype>
#include <charconv>
#include <cmath>
#include <cstddef>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "../support/temp_dir.hpp"
#include "pliant/host/fem/mesh_io.hpp"
#include "pliant/host/fem/mesh_vtk_series.hpp"
#include "pliant/host/recording.hpp"

namespace pliant::host {
namespace {

const std::string kDataDir = PLIANT_MESH_DATA_DIR;

std::string read_all(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream out;
  out << in.rdbuf();
  return out.str();
}

// A minimal XML reader for what the writer produces: declaration, elements with quoted
// attributes, character data. Fails the test on anything unbalanced or malformed.
struct XmlElement {
  std::string name;
  std::map<std::string, std::string> attributes;
  std::string text;
  std::vector<XmlElement> children;
};

bool is_name_char(char c) {
  return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_' || c == '-' ||
         c == '.' || c == ':';
}

class XmlReader {
 public:
  explicit XmlReader(std::string_view text) : text_(text) {}

  bool read(XmlElement& root) {
    skip_space();
    if (text_.substr(pos_, 5) == "<?xml") {
      const std::size_t end = text_.find("?>", pos_);
      if (end == std::string_view::npos) return false;
      pos_ = end + 2;
    }
    skip_space();
    if (!element(root)) return false;
    skip_space();
    return pos_ == text_.size();
  }

 private:
  void skip_space() {
    while (pos_ < text_.size() && std::isspace(static_cast<unsigned char>(text_[pos_]))) ++pos_;
  }

  bool name(std::string& out) {
    const std::size_t start = pos_;
    while (pos_ < text_.size() && is_name_char(text_[pos_])) ++pos_;
    out = std::string(text_.substr(start, pos_ - start));
    return !out.empty();
  }

  bool element(XmlElement& e) {
    if (pos_ >= text_.size() || text_[pos_] != '<') return false;
    ++pos_;
    if (!name(e.name)) return false;
    for (;;) {
      skip_space();
      if (pos_ >= text_.size()) return false;
      if (text_.substr(pos_, 2) == "/>") {
        pos_ += 2;
        return true;
      }
      if (text_[pos_] == '>') {
        ++pos_;
        break;
      }
      std::string key;
      if (!name(key) || pos_ + 1 >= text_.size() || text_[pos_] != '=' || text_[pos_ + 1] != '"') {
        return false;
      }
      pos_ += 2;
      const std::size_t end = text_.find('"', pos_);
      if (end == std::string_view::npos) return false;
      const std::string value(text_.substr(pos_, end - pos_));
      if (value.find('<') != std::string::npos || value.find('&') != std::string::npos) return false;
      if (!e.attributes.emplace(key, value).second) return false;  // duplicate attribute
      pos_ = end + 1;
    }
    for (;;) {
      const std::size_t next = text_.find('<', pos_);
      if (next == std::string_view::npos) return false;
      const std::string_view chars = text_.substr(pos_, next - pos_);
      if (chars.find('&') != std::string_view::npos) return false;
      e.text += chars;
      pos_ = next;
      if (text_.substr(pos_, 2) == "</") {
        pos_ += 2;
        std::string closing;
        if (!name(closing) || closing != e.name) return false;
        skip_space();
        if (pos_ >= text_.size() || text_[pos_] != '>') return false;
        ++pos_;
        return true;
      }
      e.children.emplace_back();
      if (!element(e.children.back())) return false;
    }
  }

  std::string_view text_;
  std::size_t pos_ = 0;
};

XmlElement parse_xml(const std::string& text) {
  XmlElement root;
  XmlReader reader(text);
  EXPECT_TRUE(reader.read(root)) << "malformed XML:\n" << text.substr(0, 400);
  return root;
}

const XmlElement* child(const XmlElement& e, const std::string& name) {
  for (const XmlElement& c : e.children) {
    if (c.name == name) return &c;
  }
  return nullptr;
}

const XmlElement* array_named(const XmlElement& parent, const std::string& name) {
  for (const XmlElement& c : parent.children) {
    const auto it = c.attributes.find("Name");
    if (c.name == "DataArray" && it != c.attributes.end() && it->second == name) return &c;
  }
  return nullptr;
}

double to_double(std::string_view token) {
  double value = 0.0;
  const auto result = std::from_chars(token.data(), token.data() + token.size(), value);
  EXPECT_TRUE(result.ec == std::errc() && result.ptr == token.data() + token.size()) << token;
  return value;
}

std::vector<double> numbers(const std::string& text) {
  std::vector<double> out;
  std::istringstream in(text);
  std::string token;
  while (in >> token) out.push_back(to_double(token));
  return out;
}

struct Series {
  TetMesh mesh;
  std::vector<VtkSeriesFrame> frames;
};

Series make_series() {
  Series s;
  s.mesh = read_tet_mesh(kDataDir + "/bar-6.msh");
  s.mesh.youngs_modulus.assign(static_cast<std::size_t>(s.mesh.tet_count()), 0.0);
  for (std::size_t t = 0; t < s.mesh.youngs_modulus.size(); ++t) {
    s.mesh.youngs_modulus[t] = 5e4 + 1.0 / 3.0 * static_cast<double>(t);
  }
  const double times[] = {0.0, 1.0 / 30.0, 0.1};
  for (std::size_t f = 0; f < 3; ++f) {
    VtkSeriesFrame frame;
    frame.time_s = times[f];
    VtkNamedArray displacement{"displacement", {}};
    VtkNamedArray force{"reaction_force_n", {}};
    for (std::size_t i = 0; i < s.mesh.points.size(); ++i) {
      const double d = (static_cast<double>(f) * 0.1 + 1e-17 * static_cast<double>(i)) / 7.0;
      frame.positions.push_back(s.mesh.points[i] + d);
      displacement.values.push_back(d);
      force.values.push_back(-d * 1e3);
    }
    frame.point_vectors = {displacement, force};
    VtkNamedArray stress{"von_mises_pa", {}};
    for (int t = 0; t < s.mesh.tet_count(); ++t) {
      stress.values.push_back(std::sqrt(2.0) * static_cast<double>(t + 1) * (1.0 + static_cast<double>(f)));
    }
    frame.cell_scalars = {stress};
    s.frames.push_back(frame);
  }
  return s;
}

TEST(VtkSeries, PvdAndVtuFramesAreWellFormedAndExact) {
  test_support::TempDir dir("pliant_fem_mesh_");
  const Series s = make_series();
  const std::string pvd = write_vtk_time_series(dir / "out", s.mesh, s.frames);
  EXPECT_EQ(pvd, (std::filesystem::path(dir / "out") / "frame.pvd").string());
  const XmlElement collection_file = parse_xml(read_all(pvd));
  EXPECT_EQ(collection_file.name, "VTKFile");
  EXPECT_EQ(collection_file.attributes.at("type"), "Collection");
  const XmlElement* collection = child(collection_file, "Collection");
  ASSERT_NE(collection, nullptr);
  ASSERT_EQ(collection->children.size(), 3u);
  for (std::size_t f = 0; f < 3; ++f) {
    const XmlElement& dataset = collection->children[f];
    EXPECT_EQ(dataset.name, "DataSet");
    EXPECT_EQ(to_double(dataset.attributes.at("timestep")), s.frames[f].time_s);
    const std::string file = dataset.attributes.at("file");
    EXPECT_EQ(file, "frame_00000" + std::to_string(f) + ".vtu");

    const XmlElement vtu = parse_xml(read_all((std::filesystem::path(dir / "out") / file).string()));
    EXPECT_EQ(vtu.attributes.at("type"), "UnstructuredGrid");
    const XmlElement* grid = child(vtu, "UnstructuredGrid");
    ASSERT_NE(grid, nullptr);
    const XmlElement* field = child(*grid, "FieldData");
    ASSERT_NE(field, nullptr);
    EXPECT_EQ(numbers(array_named(*field, "TimeValue")->text), std::vector<double>{s.frames[f].time_s});
    const XmlElement* piece = child(*grid, "Piece");
    ASSERT_NE(piece, nullptr);
    EXPECT_EQ(piece->attributes.at("NumberOfPoints"), "8");
    EXPECT_EQ(piece->attributes.at("NumberOfCells"), "6");
    const XmlElement* points = array_named(*child(*piece, "Points"), "Points");
    ASSERT_NE(points, nullptr);
    EXPECT_EQ(numbers(points->text), s.frames[f].positions);  // bit for bit
    const XmlElement* cells = child(*piece, "Cells");
    ASSERT_NE(cells, nullptr);
    std::vector<double> tets(s.mesh.tetrahedra.begin(), s.mesh.tetrahedra.end());
    EXPECT_EQ(numbers(array_named(*cells, "connectivity")->text), tets);
    EXPECT_EQ(numbers(array_named(*cells, "offsets")->text), (std::vector<double>{4, 8, 12, 16, 20, 24}));
    EXPECT_EQ(numbers(array_named(*cells, "types")->text), std::vector<double>(6, 10.0));
    const XmlElement* point_data = child(*piece, "PointData");
    ASSERT_NE(point_data, nullptr);
    EXPECT_EQ(point_data->attributes.at("Vectors"), "displacement");
    for (const VtkNamedArray& array : s.frames[f].point_vectors) {
      const XmlElement* data = array_named(*point_data, array.name);
      ASSERT_NE(data, nullptr) << array.name;
      EXPECT_EQ(data->attributes.at("NumberOfComponents"), "3");
      EXPECT_EQ(numbers(data->text), array.values);
    }
    const XmlElement* cell_data = child(*piece, "CellData");
    ASSERT_NE(cell_data, nullptr);
    EXPECT_EQ(numbers(array_named(*cell_data, "youngs_modulus")->text), s.mesh.youngs_modulus);
    EXPECT_EQ(numbers(array_named(*cell_data, "von_mises_pa")->text), s.frames[f].cell_scalars[0].values);
  }
}

TEST(VtkSeries, LegacyFramesReadBackWithTheRecordingReader) {
  test_support::TempDir dir("pliant_fem_mesh_");
  const Series s = make_series();
  VtkSeriesOptions options;
  options.base_name = "bar-6.run";
  options.format = VtkSeriesFormat::legacy_vtk_series;
  const std::string index = write_vtk_time_series(dir.path().string(), s.mesh, s.frames, options);
  EXPECT_EQ(index, dir / "bar-6.run.vtk.series");
  const nlohmann::json series = nlohmann::json::parse(read_all(index));
  EXPECT_EQ(series.at("file-series-version"), "1.0");
  ASSERT_EQ(series.at("files").size(), 3u);
  for (std::size_t f = 0; f < 3; ++f) {
    const nlohmann::json& entry = series.at("files")[f];
    EXPECT_EQ(entry.at("time").get<double>(), s.frames[f].time_s);
    const std::string name = entry.at("name");
    EXPECT_EQ(name, "bar-6.run_00000" + std::to_string(f) + ".vtk");
    const TetMesh frame = parse_vtk_tet_mesh(read_all(dir / name), name);
    EXPECT_EQ(frame.points, s.frames[f].positions);
    EXPECT_EQ(frame.tetrahedra, s.mesh.tetrahedra);
    EXPECT_EQ(frame.youngs_modulus, s.mesh.youngs_modulus);
  }
  // The point vectors are 3-component SCALARS after POINT_DATA.
  const std::string text = read_all(dir / "bar-6.run_000001.vtk");
  EXPECT_NE(text.find("POINT_DATA 8\nSCALARS displacement double 3\nLOOKUP_TABLE default\n"), std::string::npos);
  EXPECT_NE(text.find("SCALARS von_mises_pa double 1\n"), std::string::npos);
}

TEST(VtkSeries, StreamingWriterRefusesBadFramesWithoutChangingTheSeries) {
  test_support::TempDir dir("pliant_fem_mesh_");
  Series s = make_series();
  VtkSeriesWriter writer(dir.path().string(), s.mesh);
  writer.write_frame(s.frames[0]);
  auto expect_refused = [&](const VtkSeriesFrame& frame, const std::string& cause) {
    std::string message;
    try {
      writer.write_frame(frame);
    } catch (const MeshError& error) {
      message = error.what();
    }
    EXPECT_NE(message.find(cause), std::string::npos) << message;
    EXPECT_EQ(message.rfind("VtkSeriesWriter: ", 0), 0u) << message;
    EXPECT_EQ(writer.frame_count(), 1u);
  };
  VtkSeriesFrame frame = s.frames[1];
  frame.time_s = 0.0;
  expect_refused(frame, "frame 1: time_s 0 is not after the previous frame's 0");
  frame = s.frames[1];
  frame.positions.pop_back();
  expect_refused(frame, "frame 1: positions hold 23 values, expected 24");
  frame = s.frames[1];
  frame.positions[4] = std::nan("");
  expect_refused(frame, "frame 1: a position is not finite");
  frame = s.frames[1];
  frame.point_vectors[0].name = "bad name";
  expect_refused(frame, "point vector name 'bad name' must be 1-64 characters from [A-Za-z0-9_]");
  frame = s.frames[1];
  frame.cell_scalars[0].name = "youngs_modulus";
  expect_refused(frame, "cell scalar name 'youngs_modulus' is taken by the mesh's own array");
  frame = s.frames[1];
  frame.point_vectors[1].name = "displacement";
  expect_refused(frame, "point vector name 'displacement' appears twice");
  frame = s.frames[1];
  frame.cell_scalars[0].values.resize(5);
  expect_refused(frame, "cell scalar 'von_mises_pa' has 5 values, expected 6");

  writer.write_frame(s.frames[1]);
  const std::string first = read_all(writer.finish());
  writer.write_frame(s.frames[2]);
  const std::string second = read_all(writer.finish());
  EXPECT_EQ(parse_xml(first).children.at(0).children.size(), 2u);
  EXPECT_EQ(parse_xml(second).children.at(0).children.size(), 3u);
  // No temporary files are left behind.
  for (const auto& entry : std::filesystem::directory_iterator(dir.path())) {
    const std::string extension = entry.path().extension().string();
    EXPECT_TRUE(extension == ".pvd" || extension == ".vtu") << entry.path();
  }
}

TEST(VtkSeries, RefusesBadMeshAndOptions) {
  test_support::TempDir dir("pliant_fem_mesh_");
  TetMesh mesh = read_tet_mesh(kDataDir + "/tet.msh");
  VtkSeriesOptions options;
  options.base_name = "../escape";
  EXPECT_THROW(VtkSeriesWriter(dir.path().string(), mesh, options), MeshError);
  mesh.tetrahedra[0] = 9;
  EXPECT_THROW(VtkSeriesWriter(dir.path().string(), mesh), MeshError);
}

}  // namespace
}  // namespace pliant::host
