// Triangle surface readers: Wavefront OBJ, PLY (ASCII and binary) and STL (ASCII and binary).
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <vector>

#include "mesh_text.hpp"
#include "pliant/host/fem/surface_io.hpp"

namespace pliant::host {
namespace {

using mesh_detail::BinaryReader;
using mesh_detail::fail_byte;
using mesh_detail::fail_file;
using mesh_detail::fail_line;
using mesh_detail::iequals;
using mesh_detail::printable;
using mesh_detail::Scanner;

constexpr unsigned long long kMaxSurfacePoints = 100'000'000;

// Appends the fan triangulation of polygon `corners` (n >= 3) from its first corner.
void add_fan(TriangleSurface& surface, const std::vector<int>& corners) {
  for (std::size_t k = 1; k + 1 < corners.size(); ++k) {
    surface.triangles.push_back(corners[0]);
    surface.triangles.push_back(corners[k]);
    surface.triangles.push_back(corners[k + 1]);
  }
}

// Cause for a polygon with fewer than 3 corners or a repeated corner, else "".
std::string polygon_problem(const std::vector<int>& corners) {
  if (corners.size() < 3) {
    return "a face needs at least 3 vertices, found " + std::to_string(corners.size());
  }
  for (std::size_t a = 0; a < corners.size(); ++a) {
    for (std::size_t b = a + 1; b < corners.size(); ++b) {
      if (corners[a] == corners[b]) {
        return "a face repeats vertex " + std::to_string(corners[a]) + " (0-based)";
      }
    }
  }
  return std::string();
}

// ========================================================================================== OBJ

bool obj_ignored(std::string_view keyword) {
  static const char* const ignored[] = {"vt",  "vn",         "vp",        "g",      "o",        "s",
                                        "l",   "p",          "usemtl",    "mtllib", "usemap",   "maplib",
                                        "lod", "shadow_obj", "trace_obj", "bevel",  "c_interp", "d_interp"};
  for (const char* name : ignored) {
    if (keyword == name) return true;
  }
  return false;
}

TriangleSurface parse_obj_text(std::string_view text, const std::string& label) {
  // First pass: the vertex count, so that positive references to later vertices can be checked.
  unsigned long long total_vertices = 0;
  {
    Scanner lines(text);
    std::string_view line;
    while (lines.line(line)) {
      Scanner fields(line);
      std::string_view keyword;
      if (fields.token(keyword) && keyword == "v") ++total_vertices;
    }
  }
  if (total_vertices > kMaxSurfacePoints) {
    fail_file(label,
              std::to_string(total_vertices) + " vertices exceed the limit of " + std::to_string(kMaxSurfacePoints));
  }
  TriangleSurface surface;
  Scanner lines(text);
  std::string_view line;
  std::vector<int> corners;
  while (lines.line(line)) {
    const std::size_t number = lines.token_line();
    const std::size_t hash = line.find('#');
    if (hash != std::string_view::npos) line = line.substr(0, hash);
    Scanner fields(line);
    std::string_view keyword;
    if (!fields.token(keyword)) continue;
    std::string_view token;
    if (keyword == "v") {
      double values[7];
      std::size_t count = 0;
      while (fields.token(token)) {
        if (count == 7) fail_line(label, number, "a vertex has more than 7 values");
        if (!mesh_detail::parse_real(token, values[count])) {
          fail_line(label, number, "expected a number in a vertex, found '" + printable(token) + "'");
        }
        ++count;
      }
      if (count < 3) fail_line(label, number, "a vertex needs x y z");
      for (std::size_t axis = 0; axis < 3; ++axis) {
        if (!std::isfinite(values[axis])) {
          fail_line(label, number, "a vertex has a non-finite coordinate");
        }
        surface.points.push_back(values[axis]);
      }
    } else if (keyword == "f") {
      corners.clear();
      const auto defined = static_cast<long long>(surface.points.size() / 3);
      while (fields.token(token)) {
        const std::string_view reference = token.substr(0, token.find('/'));
        long long index = 0;
        if (!mesh_detail::parse_int(reference, index) || index == 0) {
          fail_line(label, number,
                    "expected a vertex reference (1-based or negative), found '" + printable(token) + "'");
        }
        const long long zero_based = index < 0 ? defined + index : index - 1;
        if (zero_based < 0 || static_cast<unsigned long long>(zero_based) >= total_vertices) {
          fail_line(label, number,
                    "vertex reference " + std::to_string(index) + " out of range (" + std::to_string(defined) +
                        " vertices defined so far, " + std::to_string(total_vertices) + " in the file)");
        }
        corners.push_back(static_cast<int>(zero_based));
      }
      const std::string problem = polygon_problem(corners);
      if (!problem.empty()) fail_line(label, number, problem);
      add_fan(surface, corners);
    } else if (!obj_ignored(keyword)) {
      fail_line(label, number,
                "unsupported OBJ statement '" + printable(keyword) + "' (only polygonal v/f geometry is read)");
    }
  }
  if (surface.triangles.empty()) fail_file(label, "no faces ('f' lines)");
  return surface;
}

// ========================================================================================== PLY

enum class PlyType { int8, uint8, int16, uint16, int32, uint32, float32, float64 };

bool ply_type(std::string_view name, PlyType& type) {
  struct Entry {
    const char* a;
    const char* b;
    PlyType type;
  };
  static const Entry entries[] = {{"char", "int8", PlyType::int8},        {"uchar", "uint8", PlyType::uint8},
                                  {"short", "int16", PlyType::int16},     {"ushort", "uint16", PlyType::uint16},
                                  {"int", "int32", PlyType::int32},       {"uint", "uint32", PlyType::uint32},
                                  {"float", "float32", PlyType::float32}, {"double", "float64", PlyType::float64}};
  for (const Entry& entry : entries) {
    if (name == entry.a || name == entry.b) {
      type = entry.type;
      return true;
    }
  }
  return false;
}

std::size_t ply_size(PlyType type) {
  switch (type) {
    case PlyType::int8:
    case PlyType::uint8: return 1;
    case PlyType::int16:
    case PlyType::uint16: return 2;
    case PlyType::int32:
    case PlyType::uint32:
    case PlyType::float32: return 4;
    case PlyType::float64: break;
  }
  return 8;
}

bool ply_integer(PlyType type) { return type != PlyType::float32 && type != PlyType::float64; }

struct PlyProperty {
  std::string name;
  bool list = false;
  PlyType count_type = PlyType::uint8;
  PlyType type = PlyType::float32;
};

struct PlyElement {
  std::string name;
  unsigned long long count = 0;
  std::size_t header_line = 0;
  std::vector<PlyProperty> properties;
};

class PlyReader {
 public:
  PlyReader(std::string_view text, const std::string& label) : text_(text), label_(label), scan_(text) {}

  TriangleSurface read() {
    read_header();
    const bool little = mesh_detail::host_is_little_endian();
    BinaryReader binary(text_, data_start_, binary_ && (big_endian_ == little), label_);
    for (const PlyElement& element : elements_) {
      const bool vertex = element.name == "vertex";
      const bool face = element.name == "face";
      if (element.properties.empty()) continue;  // nothing stored per item
      check_count(element, binary);
      for (unsigned long long item = 0; item < element.count; ++item) {
        double xyz[3] = {0.0, 0.0, 0.0};
        for (const PlyProperty& property : element.properties) {
          const auto describe = [&] {
            return element.name + " " + std::to_string(item) + " (of " + std::to_string(element.count) + ")";
          };
          if (property.list) {
            read_list(property, face && property.name == face_property_, binary, describe);
            continue;
          }
          const double value = read_value(property.type, binary, describe);
          if (vertex) {
            const int axis = property.name == "x" ? 0 : property.name == "y" ? 1 : property.name == "z" ? 2 : -1;
            if (axis >= 0) {
              if (!std::isfinite(value)) fail_here(binary, describe() + " has a non-finite " + property.name);
              xyz[axis] = value;
            }
          }
        }
        if (vertex) surface_.points.insert(surface_.points.end(), xyz, xyz + 3);
      }
    }
    if (!binary_) {
      std::string_view extra;
      if (scan_.token(extra)) {
        fail_line(label_, scan_.token_line(), "unexpected data after the last element ('" + printable(extra) + "')");
      }
    }
    if (surface_.triangles.empty()) fail_file(label_, "no faces");
    return std::move(surface_);
  }

 private:
  [[noreturn]] void fail_here(const BinaryReader& binary, const std::string& cause) const {
    if (binary_) fail_byte(label_, binary.pos(), cause);
    fail_line(label_, scan_.token_line(), cause);
  }

  void read_header() {
    std::string_view line;
    if (!scan_.line(line) || line != "ply") {
      fail_line(label_, 1, "not a PLY file (the first line must be 'ply')");
    }
    bool have_format = false;
    for (;;) {
      if (!scan_.line(line)) fail_line(label_, scan_.token_line(), "no end_header line");
      const std::size_t number = scan_.token_line();
      Scanner fields(line);
      std::string_view keyword;
      if (!fields.token(keyword)) continue;
      if (keyword == "end_header") break;
      if (keyword == "comment" || keyword == "obj_info") continue;
      std::string_view a;
      std::string_view b;
      std::string_view c;
      std::string_view d;
      std::string_view extra;
      const bool has_a = fields.token(a);
      const bool has_b = has_a && fields.token(b);
      const bool has_c = has_b && fields.token(c);
      const bool has_d = has_c && fields.token(d);
      const bool has_extra = has_d && fields.token(extra);
      if (keyword == "format") {
        if (have_format) fail_line(label_, number, "second format line");
        if (!has_b || has_c || b != "1.0") {
          fail_line(label_, number,
                    "expected 'format <ascii|binary_little_endian|"
                    "binary_big_endian> 1.0'");
        }
        if (a == "ascii") {
          binary_ = false;
        } else if (a == "binary_little_endian") {
          binary_ = true;
          big_endian_ = false;
        } else if (a == "binary_big_endian") {
          binary_ = true;
          big_endian_ = true;
        } else {
          fail_line(label_, number, "unknown PLY format '" + printable(a) + "'");
        }
        have_format = true;
      } else if (keyword == "element") {
        long long count = 0;
        if (!has_b || has_c || !mesh_detail::parse_int(b, count) || count < 0) {
          fail_line(label_, number, "expected 'element <name> <non-negative count>'");
        }
        for (const PlyElement& element : elements_) {
          if (element.name == a) fail_line(label_, number, "second element '" + printable(a) + "'");
        }
        PlyElement element;
        element.name = std::string(a);
        element.count = static_cast<unsigned long long>(count);
        element.header_line = number;
        elements_.push_back(std::move(element));
      } else if (keyword == "property") {
        if (elements_.empty()) fail_line(label_, number, "property before any element");
        PlyProperty property;
        if (a == "list") {
          if (!has_d || has_extra) {
            fail_line(label_, number, "expected 'property list <count type> <type> <name>'");
          }
          if (!ply_type(b, property.count_type) || !ply_type(c, property.type)) {
            fail_line(label_, number, "unknown property type in '" + printable(line) + "'");
          }
          if (!ply_integer(property.count_type)) {
            fail_line(label_, number, "a list count type must be an integer type");
          }
          property.list = true;
          property.name = std::string(d);
        } else {
          if (!has_b || has_c) fail_line(label_, number, "expected 'property <type> <name>'");
          if (!ply_type(a, property.type)) {
            fail_line(label_, number, "unknown property type '" + printable(a) + "'");
          }
          property.name = std::string(b);
        }
        for (const PlyProperty& other : elements_.back().properties) {
          if (other.name == property.name) {
            fail_line(label_, number, "second property '" + printable(property.name) + "'");
          }
        }
        elements_.back().properties.push_back(property);
      } else {
        fail_line(label_, number, "unknown header line '" + printable(line) + "'");
      }
    }
    const std::size_t end_line = scan_.token_line();
    if (!have_format) fail_line(label_, end_line, "no format line in the header");
    data_start_ = scan_.pos();
    check_elements(end_line);
  }

  void check_elements(std::size_t end_line) {
    const PlyElement* vertex = nullptr;
    const PlyElement* face = nullptr;
    for (const PlyElement& element : elements_) {
      if (element.name == "vertex") vertex = &element;
      if (element.name == "face") face = &element;
    }
    if (vertex == nullptr) fail_line(label_, end_line, "no 'vertex' element in the header");
    if (face == nullptr) fail_line(label_, end_line, "no 'face' element in the header");
    for (const char* axis : {"x", "y", "z"}) {
      bool found = false;
      for (const PlyProperty& property : vertex->properties) {
        if (property.name == axis) {
          if (property.list) fail_line(label_, vertex->header_line, "vertex x/y/z must not be lists");
          found = true;
        }
      }
      if (!found) {
        fail_line(label_, vertex->header_line, std::string("the vertex element has no property ") + axis);
      }
    }
    for (const PlyProperty& property : face->properties) {
      if (property.list && (property.name == "vertex_indices" || property.name == "vertex_index")) {
        if (!ply_integer(property.type)) {
          fail_line(label_, face->header_line, "face vertex indices must have an integer type");
        }
        face_property_ = property.name;
      }
    }
    if (face_property_.empty()) {
      fail_line(label_, face->header_line, "the face element has no list property vertex_indices (or vertex_index)");
    }
    if (vertex->count > kMaxSurfacePoints) {
      fail_line(label_, vertex->header_line,
                "vertex count " + std::to_string(vertex->count) + " exceeds the limit of " +
                    std::to_string(kMaxSurfacePoints));
    }
    vertex_count_ = vertex->count;
  }

  // The element's items must fit in the rest of the data at their smallest size.
  void check_count(const PlyElement& element, const BinaryReader& binary) const {
    std::size_t min_bytes = 0;
    for (const PlyProperty& property : element.properties) {
      min_bytes += binary_ ? ply_size(property.list ? property.count_type : property.type) : 2;
    }
    // ASCII: + 1 because the last value of the file needs no separator after it.
    const std::size_t remaining = binary_ ? binary.remaining() : scan_.remaining() + 1;
    if (element.count > remaining / min_bytes) {
      const std::string cause = "element '" + printable(element.name) + "' count " + std::to_string(element.count) +
                                " is larger than the rest of the file can hold";
      if (binary_) fail_byte(label_, binary.pos(), cause);
      fail_line(label_, element.header_line, cause);
    }
  }

  template <typename Describe>
  double read_value(PlyType type, BinaryReader& binary, const Describe& describe) {
    if (!binary_) {
      std::string_view token;
      if (!scan_.token(token)) {
        fail_line(label_, scan_.token_line(), "unexpected end of file in " + describe());
      }
      double value = 0.0;
      if (ply_integer(type)) {
        long long integer = 0;
        if (!mesh_detail::parse_int(token, integer)) {
          fail_line(label_, scan_.token_line(),
                    "expected an integer in " + describe() + ", found '" + printable(token) + "'");
        }
        value = static_cast<double>(integer);
      } else if (!mesh_detail::parse_real(token, value)) {
        fail_line(label_, scan_.token_line(),
                  "expected a number in " + describe() + ", found '" + printable(token) + "'");
      }
      return value;
    }
    switch (type) {
      case PlyType::int8: return binary.read<std::int8_t>(describe);
      case PlyType::uint8: return binary.read<std::uint8_t>(describe);
      case PlyType::int16: return binary.read<std::int16_t>(describe);
      case PlyType::uint16: return binary.read<std::uint16_t>(describe);
      case PlyType::int32: return binary.read<std::int32_t>(describe);
      case PlyType::uint32: return binary.read<std::uint32_t>(describe);
      case PlyType::float32: return static_cast<double>(binary.read<float>(describe));
      case PlyType::float64: break;
    }
    return binary.read<double>(describe);
  }

  template <typename Describe>
  void read_list(const PlyProperty& property, bool faces, BinaryReader& binary, const Describe& describe) {
    const double raw_count = read_value(property.count_type, binary, describe);
    if (raw_count < 0.0) fail_here(binary, describe() + " has a negative list length");
    const auto count = static_cast<unsigned long long>(raw_count);
    const std::size_t min_bytes = binary_ ? ply_size(property.type) : 2;
    const std::size_t remaining = binary_ ? binary.remaining() : scan_.remaining() + 1;
    if (count > remaining / min_bytes) {
      fail_here(binary, describe() + ": list length " + std::to_string(count) +
                            " is larger than the rest of the file can hold");
    }
    if (faces) corners_.clear();
    for (unsigned long long k = 0; k < count; ++k) {
      const double value = read_value(property.type, binary, describe);
      if (!faces) continue;
      if (value < 0.0 || value >= static_cast<double>(vertex_count_)) {
        fail_here(binary, describe() + ": vertex index " + format_index(value) + " out of range 0.." +
                              std::to_string(vertex_count_) + " (exclusive)");
      }
      corners_.push_back(static_cast<int>(value));
    }
    if (!faces) return;
    const std::string problem = polygon_problem(corners_);
    if (!problem.empty()) fail_here(binary, describe() + ": " + problem);
    add_fan(surface_, corners_);
  }

  static std::string format_index(double value) { return std::to_string(static_cast<long long>(value)); }

  std::string_view text_;
  const std::string& label_;
  Scanner scan_;
  bool binary_ = false;
  bool big_endian_ = false;
  std::size_t data_start_ = 0;
  std::vector<PlyElement> elements_;
  std::string face_property_;
  unsigned long long vertex_count_ = 0;
  std::vector<int> corners_;
  TriangleSurface surface_;
};

// ========================================================================================== STL

TriangleSurface parse_stl_binary(std::string_view data, const std::string& label, unsigned long long count) {
  TriangleSurface surface;
  BinaryReader in(data, 84, !mesh_detail::host_is_little_endian(), label);
  in.require(count, 50, [] { return std::string("the triangles"); });
  surface.points.reserve(static_cast<std::size_t>(count) * 9);
  surface.triangles.reserve(static_cast<std::size_t>(count) * 3);
  for (unsigned long long t = 0; t < count; ++t) {
    const auto describe = [&] { return "triangle " + std::to_string(t); };
    for (int k = 0; k < 3; ++k) in.read<float>(describe);  // normal
    for (int k = 0; k < 9; ++k) {
      const float value = in.read<float>(describe);
      if (!std::isfinite(value)) {
        fail_byte(label, in.pos() - 4, describe() + " has a non-finite coordinate");
      }
      surface.points.push_back(static_cast<double>(value));
    }
    in.read<std::uint16_t>(describe);  // attribute byte count
    const int first = static_cast<int>(3 * t);
    for (int k = 0; k < 3; ++k) surface.triangles.push_back(first + k);
  }
  return surface;
}

class StlAsciiReader {
 public:
  StlAsciiReader(std::string_view text, const std::string& label) : scan_(text), label_(label) {}

  TriangleSurface read() {
    std::string_view token;
    bool in_solid = false;
    while (scan_.token(token)) {
      if (iequals(token, "solid")) {
        if (in_solid) fail("'solid' inside a solid (missing endsolid)");
        std::string_view name;
        scan_.line(name);
        in_solid = true;
      } else if (iequals(token, "endsolid")) {
        if (!in_solid) fail("'endsolid' without 'solid'");
        std::string_view name;
        scan_.line(name);
        in_solid = false;
      } else if (iequals(token, "facet")) {
        if (!in_solid) fail("'facet' outside a solid");
        read_facet();
      } else {
        fail("expected 'facet' or 'endsolid', found '" + printable(token) + "'");
      }
    }
    if (in_solid) fail("unexpected end of file, missing 'endsolid'");
    if (surface_.triangles.empty()) fail_file(label_, "no facets");
    return std::move(surface_);
  }

 private:
  [[noreturn]] void fail(const std::string& cause) const { fail_line(label_, scan_.token_line(), cause); }

  void keyword(const char* expected) {
    std::string_view token;
    if (!scan_.token(token)) fail(std::string("unexpected end of file, expected '") + expected + "'");
    if (!iequals(token, expected)) {
      fail(std::string("expected '") + expected + "', found '" + printable(token) + "'");
    }
  }

  double number(bool check_finite) {
    std::string_view token;
    if (!scan_.token(token)) fail("unexpected end of file, expected a number");
    double value = 0.0;
    if (!mesh_detail::parse_real(token, value)) {
      fail("expected a number, found '" + printable(token) + "'");
    }
    if (check_finite && !std::isfinite(value)) fail("a vertex has a non-finite coordinate");
    return value;
  }

  void read_facet() {
    keyword("normal");
    for (int k = 0; k < 3; ++k) number(false);
    keyword("outer");
    keyword("loop");
    if (surface_.points.size() / 3 + 3 > kMaxSurfacePoints) fail("too many facets");
    const int first = static_cast<int>(surface_.points.size() / 3);
    int vertices = 0;
    std::string_view token;
    for (;;) {
      if (!scan_.token(token)) fail("unexpected end of file in a facet");
      if (iequals(token, "endloop")) break;
      if (!iequals(token, "vertex")) {
        fail("expected 'vertex' or 'endloop', found '" + printable(token) + "'");
      }
      if (vertices == 3) fail("a facet has more than 3 vertices");
      for (int k = 0; k < 3; ++k) surface_.points.push_back(number(true));
      ++vertices;
    }
    if (vertices != 3) fail("a facet has " + std::to_string(vertices) + " vertices, expected 3");
    keyword("endfacet");
    for (int k = 0; k < 3; ++k) surface_.triangles.push_back(first + k);
  }

  Scanner scan_;
  const std::string& label_;
  TriangleSurface surface_;
};

}  // namespace

TriangleSurface parse_obj(std::string_view text, const std::string& file_label) {
  return parse_obj_text(text, file_label);
}

TriangleSurface parse_ply(std::string_view text, const std::string& file_label) {
  return PlyReader(text, file_label).read();
}

TriangleSurface parse_stl(std::string_view text, const std::string& file_label) {
  unsigned long long count = 0;
  if (text.size() >= 84) {
    BinaryReader header(text, 80, !mesh_detail::host_is_little_endian(), file_label);
    count = header.read<std::uint32_t>([] { return std::string("the triangle count"); });
    if (84 + 50 * count == text.size()) return parse_stl_binary(text, file_label, count);
  }
  std::size_t start = 0;
  while (start < text.size() && mesh_detail::is_space(text[start])) ++start;
  if (text.size() - start >= 5 && iequals(text.substr(start, 5), "solid")) {
    return StlAsciiReader(text, file_label).read();
  }
  if (text.size() < 84) {
    fail_file(file_label, "not an STL file: too short for binary STL (" + std::to_string(text.size()) +
                              " bytes) and no 'solid' keyword");
  }
  fail_file(file_label, "binary STL size mismatch: the header declares " + std::to_string(count) + " triangles (" +
                            std::to_string(84 + 50 * count) + " bytes), the file has " + std::to_string(text.size()) +
                            " bytes");
}

}  // namespace pliant::host
