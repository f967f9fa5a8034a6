// TetGen .node/.ele reader and writer (file formats of the TetGen 1.5 manual, section 5).
#include <cmath>
#include <cstddef>
#include <ostream>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "mesh_text.hpp"
#include "pliant/host/fem/mesh_io.hpp"

namespace pliant::host {
namespace {

using mesh_detail::fail_line;
using mesh_detail::printable;
using mesh_detail::Scanner;

constexpr long long kMaxPoints = 100'000'000;
constexpr long long kMaxTets = 400'000'000;

// Non-blank lines with '#' comments removed, split into tokens.
class TetGenLines {
 public:
  TetGenLines(std::string_view text, const std::string& label) : scan_(text), label_(label) {}

  /// Next non-blank line's tokens; false at the end of the text.
  bool next(std::vector<std::string_view>& tokens) {
    std::string_view line;
    while (scan_.line(line)) {
      const std::size_t hash = line.find('#');
      if (hash != std::string_view::npos) line = line.substr(0, hash);
      tokens.clear();
      Scanner fields(line);
      std::string_view token;
      while (fields.token(token)) tokens.push_back(token);
      if (!tokens.empty()) return true;
    }
    return false;
  }

  std::size_t line() const { return scan_.token_line(); }
  std::size_t remaining() const { return scan_.remaining(); }

  [[noreturn]] void fail(const std::string& cause) const { fail_line(label_, line(), cause); }

  long long integer(std::string_view token, const std::string& what) const {
    long long value = 0;
    if (!mesh_detail::parse_int(token, value)) {
      fail("expected an integer for " + what + ", found '" + printable(token) + "'");
    }
    return value;
  }

  double number(std::string_view token, const std::string& what) const {
    double value = 0.0;
    if (!mesh_detail::parse_real(token, value)) {
      fail("expected a number for " + what + ", found '" + printable(token) + "'");
    }
    return value;
  }

  // A header count: not negative, at most `limit`, and each item needs a line of at least
  // `min_bytes` bytes in the rest of the file.
  std::size_t count(std::string_view token, const std::string& what, long long limit, std::size_t min_bytes) const {
    const long long value = integer(token, what);
    if (value < 0) fail(what + " must not be negative (found " + std::to_string(value) + ")");
    if (value > limit) {
      fail(what + " " + std::to_string(value) + " exceeds the limit of " + std::to_string(limit));
    }
    // + 1: the last line may lack its newline.
    if (static_cast<unsigned long long>(value) > (remaining() + 1) / min_bytes) {
      fail(what + " " + std::to_string(value) + " is larger than the rest of the file can hold");
    }
    return static_cast<std::size_t>(value);
  }

  void expect_end(std::size_t declared, const char* items) {
    std::vector<std::string_view> tokens;
    if (next(tokens)) {
      fail("unexpected data after the " + std::to_string(declared) + " " + items + " the header declares ('" +
           printable(tokens.front()) + "')");
    }
  }

 private:
  Scanner scan_;
  const std::string& label_;
};

}  // namespace

TetGenNodes parse_tetgen_node(std::string_view text, const std::string& file_label) {
  TetGenLines lines(text, file_label);
  std::vector<std::string_view> tokens;
  if (!lines.next(tokens)) mesh_detail::fail_file(file_label, "empty .node file (no header)");
  if (tokens.size() > 4) lines.fail("the .node header has more than 4 values");
  const std::size_t count = lines.count(tokens[0], "the point count", kMaxPoints, 8);
  if (count == 0) lines.fail("the point count must be positive");
  const long long dimension = tokens.size() > 1 ? lines.integer(tokens[1], "the dimension") : 3;
  if (dimension != 3) {
    lines.fail("dimension " + std::to_string(dimension) + " is not supported (must be 3)");
  }
  const long long attributes = tokens.size() > 2 ? lines.integer(tokens[2], "the attribute count") : 0;
  if (attributes < 0 || attributes > 1000) {
    lines.fail("attribute count " + std::to_string(attributes) + " must be 0 to 1000");
  }
  const long long markers = tokens.size() > 3 ? lines.integer(tokens[3], "the marker flag") : 0;
  if (markers != 0 && markers != 1) lines.fail("the boundary marker flag must be 0 or 1");
  const std::size_t values = 4 + static_cast<std::size_t>(attributes + markers);

  TetGenNodes nodes;
  for (std::size_t i = 0; i < count; ++i) {
    if (!lines.next(tokens)) {
      lines.fail("unexpected end of file after " + std::to_string(i) + " of " + std::to_string(count) + " points");
    }
    if (tokens.size() < values) {
      lines.fail("point line has " + std::to_string(tokens.size()) + " values, the header asks " + "for " +
                 std::to_string(values));
    }
    const long long index = lines.integer(tokens[0], "the point number");
    if (i == 0) {
      if (index != 0 && index != 1) lines.fail("the first point must be numbered 0 or 1");
      nodes.first_index = static_cast<int>(index);
    } else if (index != nodes.first_index + static_cast<long long>(i)) {
      lines.fail("point number " + std::to_string(index) + " out of sequence (expected " +
                 std::to_string(nodes.first_index + static_cast<long long>(i)) + ")");
    }
    for (std::size_t axis = 1; axis <= 3; ++axis) {
      const double value = lines.number(tokens[axis], "a coordinate of point " + std::to_string(index));
      if (!std::isfinite(value)) {
        lines.fail("point " + std::to_string(index) + " has a non-finite coordinate");
      }
      nodes.points.push_back(value);
    }
    for (std::size_t k = 4; k < 4 + static_cast<std::size_t>(attributes); ++k) {
      lines.number(tokens[k], "an attribute of point " + std::to_string(index));
    }
    if (markers == 1) lines.integer(tokens[values - 1], "the marker of point " + std::to_string(index));
  }
  lines.expect_end(count, "points");
  return nodes;
}

TetMesh parse_tetgen_ele(std::string_view text, const std::string& file_label, TetGenNodes nodes,
                         MeshReadReport* report) {
  if (report != nullptr) *report = MeshReadReport();
  if (nodes.points.empty() || nodes.points.size() % 3 != 0 || (nodes.first_index != 0 && nodes.first_index != 1)) {
    mesh_detail::fail_file(file_label, "the .node points are empty or inconsistent");
  }
  TetGenLines lines(text, file_label);
  std::vector<std::string_view> tokens;
  if (!lines.next(tokens)) mesh_detail::fail_file(file_label, "empty .ele file (no header)");
  if (tokens.size() > 3) lines.fail("the .ele header has more than 3 values");
  const std::size_t count = lines.count(tokens[0], "the tetrahedron count", kMaxTets, 10);
  const long long corners = tokens.size() > 1 ? lines.integer(tokens[1], "nodes per tetrahedron") : 4;
  if (corners == 10) {
    lines.fail(
        "second-order tetrahedra (10 nodes, tetgen -o2) are not supported: only linear "
        "4-node tetrahedra are read");
  }
  if (corners != 4) lines.fail("nodes per tetrahedron must be 4, found " + std::to_string(corners));
  const long long attributes = tokens.size() > 2 ? lines.integer(tokens[2], "the attribute count") : 0;
  if (attributes < 0 || attributes > 1000) {
    lines.fail("attribute count " + std::to_string(attributes) + " must be 0 to 1000");
  }
  const std::size_t values = 5 + static_cast<std::size_t>(attributes);
  const long long point_count = static_cast<long long>(nodes.points.size() / 3);

  TetMesh mesh;
  mesh.points = std::move(nodes.points);
  for (std::size_t t = 0; t < count; ++t) {
    if (!lines.next(tokens)) {
      lines.fail("unexpected end of file after " + std::to_string(t) + " of " + std::to_string(count) + " tetrahedra");
    }
    if (tokens.size() < values) {
      lines.fail("tetrahedron line has " + std::to_string(tokens.size()) + " values, the header asks for " +
                 std::to_string(values));
    }
    lines.integer(tokens[0], "the tetrahedron number");
    int tet[4];
    for (std::size_t k = 0; k < 4; ++k) {
      const long long index = lines.integer(tokens[k + 1], "a point of tetrahedron " + std::to_string(t));
      const long long zero_based = index - nodes.first_index;
      if (zero_based < 0 || zero_based >= point_count) {
        lines.fail("tetrahedron " + std::to_string(t) + ": point " + std::to_string(index) + " out of range " +
                   std::to_string(nodes.first_index) + ".." + std::to_string(point_count - 1 + nodes.first_index));
      }
      tet[k] = static_cast<int>(zero_based);
    }
    for (std::size_t k = 5; k < values; ++k) {
      lines.number(tokens[k], "an attribute of tetrahedron " + std::to_string(t));
    }
    const std::string cause = mesh_detail::orient_tet(mesh.points.data(), tet, t, report);
    if (!cause.empty()) lines.fail(cause);
    mesh.tetrahedra.insert(mesh.tetrahedra.end(), tet, tet + 4);
  }
  lines.expect_end(count, "tetrahedra");
  mesh_detail::finish_report(mesh, file_label, report);
  return mesh;
}

void write_tetgen(const TetMesh& mesh, std::ostream& node_out, std::ostream& ele_out, int first_index) {
  mesh_detail::check_writable(mesh, "write_tetgen");
  if (first_index != 0 && first_index != 1) {
    mesh_detail::fail_file("write_tetgen", "first_index must be 0 or 1");
  }
  const std::size_t points = mesh.points.size() / 3;
  const std::size_t tets = mesh.tetrahedra.size() / 4;
  const auto base = static_cast<std::size_t>(first_index);
  node_out << "# pliant: " << points << " points, numbered from " << first_index << "\n" << points << " 3 0 0\n";
  std::string line;
  for (std::size_t i = 0; i < points; ++i) {
    line = std::to_string(i + base);
    for (std::size_t axis = 0; axis < 3; ++axis) {
      line.push_back(' ');
      line += mesh_detail::format_double(mesh.points[3 * i + axis]);
    }
    node_out << line << '\n';
  }
  ele_out << "# pliant: " << tets << " tetrahedra\n" << tets << " 4 0\n";
  for (std::size_t t = 0; t < tets; ++t) {
    ele_out << t + base;
    for (std::size_t k = 0; k < 4; ++k) {
      ele_out << ' ' << static_cast<std::size_t>(mesh.tetrahedra[4 * t + k]) + base;
    }
    ele_out << '\n';
  }
}

}  // namespace pliant::host
