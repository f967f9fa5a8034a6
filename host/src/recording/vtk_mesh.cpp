// mesh.vtk of recording format v1: legacy VTK ASCII UNSTRUCTURED_GRID with tetrahedra only.
// Both cell layouts are read: the classic `CELLS m size` list (versions up to 4.2) and the
// `CELLS offsets size` + OFFSETS/CONNECTIVITY arrays of version 5.1.
#include "pliant/host/vtk_mesh.hpp"

#include <cmath>
#include <ostream>
#include <stdexcept>
#include <string>
#include <vector>

#include "pliant/host/text_fields.hpp"

namespace pliant::host {
namespace {

using detail::equals_ignoring_case;
using detail::fail_at;
using detail::NumberStatus;
using detail::printable;

constexpr long long kTetrahedronType = 10;

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\v' || c == '\f'; }

// Whitespace-separated tokens with the line each starts on.
class Tokenizer {
 public:
  Tokenizer(std::string_view text, std::size_t offset, std::size_t line)
      : text_(text), pos_(offset), line_(line), token_line_(line > 1 ? line - 1 : 1) {}

  bool next(std::string_view& token) {
    skip_space();
    if (pos_ >= text_.size()) return false;
    const std::size_t start = pos_;
    while (pos_ < text_.size() && !is_space(text_[pos_])) ++pos_;
    token = text_.substr(start, pos_ - start);
    token_line_ = line_;
    return true;
  }

  bool peek(std::string_view& token) {
    const std::size_t pos = pos_;
    const std::size_t line = line_;
    const std::size_t token_line = token_line_;
    const bool found = next(token);
    pos_ = pos;
    line_ = line;
    token_line_ = token_line;
    return found;
  }

  // A METADATA block runs to the first blank line (as VTK's own reader treats it).
  void skip_to_blank_line() {
    bool line_blank = false;  // the rest of the METADATA keyword's line does not count
    while (pos_ < text_.size()) {
      const char c = text_[pos_++];
      if (c == '\n') {
        if (line_blank) {
          ++line_;
          return;
        }
        ++line_;
        line_blank = true;
      } else if (!is_space(c)) {
        line_blank = false;
      }
    }
  }

  std::size_t line() const { return token_line_; }  ///< line of the latest token

 private:
  void skip_space() {
    while (pos_ < text_.size() && is_space(text_[pos_])) {
      if (text_[pos_] == '\n') ++line_;
      ++pos_;
    }
  }

  std::string_view text_;
  std::size_t pos_;
  std::size_t line_;
  std::size_t token_line_;
};

bool is_numeric_type(std::string_view type) {
  static const char* const types[] = {
      "float",          "double",         "int",          "unsigned_int",  "long",         "unsigned_long",
      "short",          "unsigned_short", "char",         "unsigned_char", "vtktypeint8",  "vtktypeuint8",
      "vtktypeint16",   "vtktypeuint16",  "vtktypeint32", "vtktypeuint32", "vtktypeint64", "vtktypeuint64",
      "vtktypefloat32", "vtktypefloat64"};
  for (const char* known : types) {
    if (equals_ignoring_case(type, known)) return true;
  }
  return false;
}

bool is_integer_type(std::string_view type) {
  return is_numeric_type(type) && !equals_ignoring_case(type, "float") && !equals_ignoring_case(type, "double") &&
         !equals_ignoring_case(type, "vtktypefloat32") && !equals_ignoring_case(type, "vtktypefloat64");
}

class VtkReader {
 public:
  VtkReader(std::string_view text, const std::string& label) : text_(text), label_(label), tokens_(text, 0, 1) {}

  TetMesh read() {
    read_header();
    std::string_view token = expect("'DATASET UNSTRUCTURED_GRID'");
    if (!equals_ignoring_case(token, "DATASET")) {
      fail(tokens_.line(), "expected 'DATASET UNSTRUCTURED_GRID', found '" + printable(token) + "'");
    }
    const std::string_view type = expect("dataset type after DATASET");
    if (!equals_ignoring_case(type, "UNSTRUCTURED_GRID")) {
      fail(tokens_.line(), "dataset type '" + printable(type) + "' is not supported, expected UNSTRUCTURED_GRID");
    }
    while (tokens_.next(token)) read_section(token);
    const std::size_t last = tokens_.line();
    if (!have_points_) fail(last, "no POINTS section");
    if (!have_cells_) fail(last, "no CELLS section");
    if (!have_cell_types_) fail(last, "no CELL_TYPES section");
    return std::move(mesh_);
  }

 private:
  [[noreturn]] void fail(std::size_t line, const std::string& cause) { fail_at(label_, line, cause); }

  void read_header() {
    detail::LineReader lines(text_);
    std::string_view line;
    if (!lines.next(line) || line.substr(0, 22) != "# vtk DataFile Version") {
      fail(1, "not a legacy VTK file (expected '# vtk DataFile Version ...')");
    }
    if (!lines.next(line)) fail(1, "unexpected end of file in the header");  // title
    if (!lines.next(line)) fail(2, "unexpected end of file in the header");
    while (!line.empty() && is_space(line.back())) line.remove_suffix(1);
    while (!line.empty() && is_space(line.front())) line.remove_prefix(1);
    if (equals_ignoring_case(line, "BINARY")) {
      fail(3, "binary VTK files are not supported, write ASCII");
    }
    if (!equals_ignoring_case(line, "ASCII")) {
      fail(3, "expected ASCII, found '" + printable(line) + "'");
    }
    const std::size_t bom = text_.substr(0, 3) == "\xEF\xBB\xBF" ? 3 : 0;
    tokens_ = Tokenizer(text_, bom + lines.offset(), 4);
  }

  // `describe` names the expected item; it is only called to build an error message, which
  // keeps the per-number cost of large meshes free of string formatting.
  template <typename Describe>
  std::string_view next_token(const Describe& describe) {
    std::string_view token;
    if (!tokens_.next(token)) {
      fail(tokens_.line(), "unexpected end of file, expected " + describe());
    }
    return token;
  }

  std::string_view expect(const std::string& what) {
    return next_token([&] { return what; });
  }

  // A count that cannot exceed the file length, so later arithmetic on it cannot overflow.
  std::size_t read_count(const std::string& what) {
    const std::string_view token = expect(what);
    long long value = 0;
    const NumberStatus status = detail::parse_integer(token, value);
    if (status == NumberStatus::not_a_number || value < 0) {
      fail(tokens_.line(), what + ": expected a non-negative integer, found '" + printable(token) + "'");
    }
    if (status == NumberStatus::out_of_range || static_cast<unsigned long long>(value) > text_.size()) {
      fail(tokens_.line(), what + " " + printable(token) + " is larger than the file can hold");
    }
    return static_cast<std::size_t>(value);
  }

  template <typename Describe>
  double read_number(const Describe& describe) {
    const std::string_view token = next_token(describe);
    double value = 0.0;
    if (detail::parse_double(token, value) != NumberStatus::ok) {
      fail(tokens_.line(), "expected a number for " + describe() + ", found '" + printable(token) +
                               "' (does the count match the data?)");
    }
    return value;
  }

  template <typename Describe>
  long long read_integer(const Describe& describe) {
    const std::string_view token = next_token(describe);
    long long value = 0;
    if (detail::parse_integer(token, value) != NumberStatus::ok) {
      fail(tokens_.line(), "expected an integer for " + describe() + ", found '" + printable(token) +
                               "' (does the count match the data?)");
    }
    return value;
  }

  void read_type(const std::string& what, bool integer_only) {
    const std::string_view type = expect("data type of " + what);
    if (integer_only ? !is_integer_type(type) : !is_numeric_type(type)) {
      fail(tokens_.line(), "unsupported data type '" + printable(type) + "' for " + what);
    }
  }

  void read_section(std::string_view keyword) {
    const std::size_t line = tokens_.line();
    if (equals_ignoring_case(keyword, "POINTS")) {
      read_points(line);
    } else if (equals_ignoring_case(keyword, "CELLS")) {
      read_cells(line);
    } else if (equals_ignoring_case(keyword, "CELL_TYPES")) {
      read_cell_types(line);
    } else if (equals_ignoring_case(keyword, "CELL_DATA")) {
      if (!have_cell_types_) fail(line, "CELL_DATA before CELLS and CELL_TYPES");
      const std::size_t count = read_count("CELL_DATA count");
      if (count != cell_count()) {
        fail(line, "CELL_DATA count " + std::to_string(count) + " does not match the " + std::to_string(cell_count()) +
                       " cells");
      }
      attributes_ = Attributes::cell;
    } else if (equals_ignoring_case(keyword, "POINT_DATA")) {
      if (!have_points_) fail(line, "POINT_DATA before POINTS");
      const std::size_t count = read_count("POINT_DATA count");
      if (count != point_count()) {
        fail(line, "POINT_DATA count " + std::to_string(count) + " does not match the " +
                       std::to_string(point_count()) + " points");
      }
      attributes_ = Attributes::point;
    } else if (equals_ignoring_case(keyword, "SCALARS")) {
      read_scalars(line);
    } else if (equals_ignoring_case(keyword, "METADATA")) {
      tokens_.skip_to_blank_line();
    } else {
      const char first = keyword.front();
      const bool word = (first >= 'A' && first <= 'Z') || (first >= 'a' && first <= 'z');
      fail(line, word ? "unsupported section '" + printable(keyword) + "'"
                      : "unexpected '" + printable(keyword) +
                            "' where a section keyword belongs (does the count before it "
                            "match its data?)");
    }
  }

  void read_points(std::size_t line) {
    if (have_points_) fail(line, "second POINTS section");
    const std::size_t count = read_count("POINTS count");
    if (count == 0) fail(line, "POINTS count must be positive");
    if (count > static_cast<std::size_t>(detail::kMaxParticles)) {
      fail(line,
           "POINTS count " + std::to_string(count) + " exceeds the limit of " + std::to_string(detail::kMaxParticles));
    }
    read_type("POINTS", false);
    for (std::size_t i = 0; i < count; ++i) {
      for (int axis = 0; axis < 3; ++axis) {
        const double value = read_number([&] { return "point " + std::to_string(i) + " of " + std::to_string(count); });
        if (!std::isfinite(value)) {
          fail(tokens_.line(), "point " + std::to_string(i) + " has a non-finite coordinate");
        }
        mesh_.points.push_back(value);
      }
    }
    have_points_ = true;
  }

  int read_point_index(std::size_t cell) {
    const long long index = read_integer([&] { return "a point index of cell " + std::to_string(cell); });
    if (index < 0 || static_cast<unsigned long long>(index) >= point_count()) {
      fail(tokens_.line(), "cell " + std::to_string(cell) + ": point index " + std::to_string(index) +
                               " out of range 0.." + std::to_string(point_count() - 1));
    }
    return static_cast<int>(index);
  }

  void check_distinct(std::size_t cell) {
    const int* tet = mesh_.tetrahedra.data() + mesh_.tetrahedra.size() - 4;
    for (int a = 0; a < 4; ++a) {
      for (int b = a + 1; b < 4; ++b) {
        if (tet[a] == tet[b]) {
          fail(tokens_.line(), "cell " + std::to_string(cell) + " repeats point " + std::to_string(tet[a]));
        }
      }
    }
  }

  [[noreturn]] void fail_not_tetrahedron(std::size_t line, std::size_t cell, long long points) {
    fail(line, "cell " + std::to_string(cell) + " has " + std::to_string(points) +
                   " points, only tetrahedra (4 points) are supported");
  }

  void read_cells(std::size_t line) {
    if (have_cells_) fail(line, "second CELLS section");
    if (!have_points_) fail(line, "CELLS before POINTS");
    const std::size_t first = read_count("CELLS count");
    const std::size_t size = read_count("CELLS size");
    std::string_view next;
    if (tokens_.peek(next) && equals_ignoring_case(next, "OFFSETS")) {
      read_offset_cells(line, first, size);
    } else {
      read_classic_cells(line, first, size);
    }
    if (cell_count() == 0) fail(line, "the mesh has no cells");
    have_cells_ = true;
  }

  void read_classic_cells(std::size_t line, std::size_t count, std::size_t size) {
    std::size_t used = 0;
    for (std::size_t cell = 0; cell < count; ++cell) {
      const long long points = read_integer([&] { return "the point count of cell " + std::to_string(cell); });
      if (points != 4) fail_not_tetrahedron(tokens_.line(), cell, points);
      used += 5;
      if (used > size) {
        fail(tokens_.line(), "CELLS size " + std::to_string(size) + " is smaller than the cell list (at cell " +
                                 std::to_string(cell) + ")");
      }
      for (int k = 0; k < 4; ++k) mesh_.tetrahedra.push_back(read_point_index(cell));
      check_distinct(cell);
    }
    if (used != size) {
      fail(line, "CELLS size " + std::to_string(size) + " does not match the " + std::to_string(used) +
                     " values of its " + std::to_string(count) + " cells");
    }
  }

  void read_offset_cells(std::size_t line, std::size_t offset_count, std::size_t size) {
    if (offset_count == 0) fail(line, "CELLS offsets count must be at least 1");
    expect("OFFSETS");
    read_type("OFFSETS", true);
    long long previous = 0;
    for (std::size_t i = 0; i < offset_count; ++i) {
      const long long offset = read_integer([&] { return "offset " + std::to_string(i); });
      if (i == 0 && offset != 0) fail(tokens_.line(), "OFFSETS must start at 0");
      // Compared before subtracting: previous >= 0, so offset - previous cannot overflow.
      if (i > 0 && offset < previous) fail(tokens_.line(), "OFFSETS must not decrease");
      if (i > 0 && offset - previous != 4) {
        fail_not_tetrahedron(tokens_.line(), i - 1, offset - previous);
      }
      previous = offset;
    }
    if (static_cast<unsigned long long>(previous) != size) {
      fail(line, "CELLS connectivity size " + std::to_string(size) + " does not match the last offset " +
                     std::to_string(previous));
    }
    const std::string_view keyword = expect("CONNECTIVITY");
    if (!equals_ignoring_case(keyword, "CONNECTIVITY")) {
      fail(tokens_.line(),
           "expected CONNECTIVITY after the offsets, found '" + printable(keyword) + "' (does the CELLS count match?)");
    }
    read_type("CONNECTIVITY", true);
    for (std::size_t cell = 0; cell + 1 < offset_count; ++cell) {
      for (int k = 0; k < 4; ++k) mesh_.tetrahedra.push_back(read_point_index(cell));
      check_distinct(cell);
    }
  }

  void read_cell_types(std::size_t line) {
    if (have_cell_types_) fail(line, "second CELL_TYPES section");
    if (!have_cells_) fail(line, "CELL_TYPES before CELLS");
    const std::size_t count = read_count("CELL_TYPES count");
    if (count != cell_count()) {
      fail(line, "CELL_TYPES count " + std::to_string(count) + " does not match the " + std::to_string(cell_count()) +
                     " cells");
    }
    for (std::size_t cell = 0; cell < count; ++cell) {
      const long long type = read_integer([&] { return "the type of cell " + std::to_string(cell); });
      if (type != kTetrahedronType) {
        fail(tokens_.line(), "cell " + std::to_string(cell) + " has type " + std::to_string(type) +
                                 ", only tetrahedra (type 10) are supported");
      }
    }
    have_cell_types_ = true;
  }

  void read_scalars(std::size_t line) {
    if (attributes_ == Attributes::none) fail(line, "SCALARS outside CELL_DATA or POINT_DATA");
    const std::string_view name = expect("the SCALARS name");
    read_type("SCALARS " + printable(name), false);
    long long components = 1;
    std::string_view next;
    long long parsed = 0;
    if (tokens_.peek(next) && detail::parse_integer(next, parsed) == NumberStatus::ok) {
      tokens_.next(next);
      components = parsed;
      if (components < 1 || components > 4) {
        fail(tokens_.line(), "SCALARS component count must be 1 to 4");
      }
    }
    const std::string_view table = expect("LOOKUP_TABLE");
    if (!equals_ignoring_case(table, "LOOKUP_TABLE")) {
      fail(tokens_.line(), "expected LOOKUP_TABLE after SCALARS, found '" + printable(table) + "'");
    }
    const std::string_view table_name = expect("the LOOKUP_TABLE name");
    if (table_name != "default") {
      fail(tokens_.line(), "only 'LOOKUP_TABLE default' is supported");
    }
    const bool per_cell = attributes_ == Attributes::cell;
    const std::size_t tuples = per_cell ? cell_count() : point_count();
    if (per_cell && name == "youngs_modulus") {
      if (components != 1) fail(line, "youngs_modulus must have 1 component");
      if (!mesh_.youngs_modulus.empty()) fail(line, "second youngs_modulus array");
      for (std::size_t cell = 0; cell < tuples; ++cell) {
        const double value = read_number([&] { return "youngs_modulus of cell " + std::to_string(cell); });
        if (!std::isfinite(value) || !(value > 0.0)) {
          fail(tokens_.line(), "youngs_modulus of cell " + std::to_string(cell) + " must be positive and finite");
        }
        mesh_.youngs_modulus.push_back(value);
      }
      return;
    }
    // Other arrays are not part of the recording; their values are only checked to be numbers.
    const std::size_t values = tuples * static_cast<std::size_t>(components);
    for (std::size_t i = 0; i < values; ++i) {
      read_number([&] { return "value " + std::to_string(i) + " of SCALARS " + printable(name); });
    }
  }

  std::size_t point_count() const { return mesh_.points.size() / 3; }
  std::size_t cell_count() const { return mesh_.tetrahedra.size() / 4; }

  enum class Attributes { none, cell, point };

  std::string_view text_;
  const std::string& label_;
  Tokenizer tokens_;
  TetMesh mesh_;
  bool have_points_ = false;
  bool have_cells_ = false;
  bool have_cell_types_ = false;
  Attributes attributes_ = Attributes::none;
};

void append_number(std::string& line, double value) {
  if (!line.empty()) line.push_back(' ');
  line += detail::format_double(value);
}

}  // namespace

TetMesh parse_vtk_tet_mesh(std::string_view text, const std::string& file_label) {
  return VtkReader(text, file_label).read();
}

void write_vtk_tet_mesh(const TetMesh& mesh, std::ostream& out) {
  const std::size_t points = mesh.points.size() / 3;
  const std::size_t cells = mesh.tetrahedra.size() / 4;
  if (mesh.points.size() % 3 != 0 || mesh.tetrahedra.size() % 4 != 0) {
    throw std::runtime_error("write_vtk_tet_mesh: points or tetrahedra have a partial entry");
  }
  if (!mesh.youngs_modulus.empty() && mesh.youngs_modulus.size() != cells) {
    throw std::runtime_error("write_vtk_tet_mesh: youngs_modulus needs one value per cell");
  }
  for (const int index : mesh.tetrahedra) {
    if (index < 0 || static_cast<std::size_t>(index) >= points) {
      throw std::runtime_error("write_vtk_tet_mesh: point index " + std::to_string(index) + " out of range");
    }
  }
  out << "# vtk DataFile Version 3.0\npliant rest mesh\nASCII\nDATASET UNSTRUCTURED_GRID\n";
  out << "POINTS " << points << " double\n";
  std::string line;
  for (std::size_t i = 0; i < points; ++i) {
    line.clear();
    for (std::size_t axis = 0; axis < 3; ++axis) append_number(line, mesh.points[3 * i + axis]);
    out << line << '\n';
  }
  out << "CELLS " << cells << ' ' << 5 * cells << '\n';
  for (std::size_t c = 0; c < cells; ++c) {
    out << '4';
    for (std::size_t k = 0; k < 4; ++k) out << ' ' << mesh.tetrahedra[4 * c + k];
    out << '\n';
  }
  out << "CELL_TYPES " << cells << '\n';
  for (std::size_t c = 0; c < cells; ++c) out << kTetrahedronType << '\n';
  if (!mesh.youngs_modulus.empty()) {
    out << "CELL_DATA " << cells << "\nSCALARS youngs_modulus double 1\nLOOKUP_TABLE default\n";
    for (const double value : mesh.youngs_modulus) out << detail::format_double(value) << '\n';
  }
}

}  // namespace pliant::host
