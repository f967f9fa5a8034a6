// gmsh MSH reader (4.1 ASCII and binary, 2.x ASCII) and MSH 4.1 ASCII writer.
//
// Reference: the "MSH file format" chapter of the gmsh manual. Element data lines are read one
// per line in ASCII, which is how every MSH writer lays them out; that lets elements of unknown
// lower-dimensional types be skipped without knowing their node count.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <ostream>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "mesh_text.hpp"
#include "pliant/host/fem/mesh_io.hpp"

namespace pliant::host {
namespace {

using mesh_detail::BinaryReader;
using mesh_detail::printable;
using mesh_detail::Scanner;

// Upper bounds that keep every index an int and every size computation far from overflow.
constexpr unsigned long long kMaxNodes = 100'000'000;
constexpr unsigned long long kMaxElements = 400'000'000;

struct ElementType {
  int type;
  int nodes;
  int dimension;
  const char* name;
};

// gmsh element types 1-31 (the fixed-order types; higher types are rare and refused).
constexpr ElementType kElementTypes[] = {
    {1, 2, 1, "2-node line"},
    {2, 3, 2, "3-node triangle"},
    {3, 4, 2, "4-node quadrangle"},
    {4, 4, 3, "4-node tetrahedron"},
    {5, 8, 3, "8-node hexahedron"},
    {6, 6, 3, "6-node prism"},
    {7, 5, 3, "5-node pyramid"},
    {8, 3, 1, "3-node line"},
    {9, 6, 2, "6-node triangle"},
    {10, 9, 2, "9-node quadrangle"},
    {11, 10, 3, "10-node second-order tetrahedron"},
    {12, 27, 3, "27-node hexahedron"},
    {13, 18, 3, "18-node prism"},
    {14, 14, 3, "14-node pyramid"},
    {15, 1, 0, "1-node point"},
    {16, 8, 2, "8-node quadrangle"},
    {17, 20, 3, "20-node hexahedron"},
    {18, 15, 3, "15-node prism"},
    {19, 13, 3, "13-node pyramid"},
    {20, 9, 2, "9-node incomplete triangle"},
    {21, 10, 2, "10-node triangle"},
    {22, 12, 2, "12-node incomplete triangle"},
    {23, 15, 2, "15-node triangle"},
    {24, 15, 2, "15-node incomplete triangle"},
    {25, 21, 2, "21-node triangle"},
    {26, 4, 1, "4-node line"},
    {27, 5, 1, "5-node line"},
    {28, 6, 1, "6-node line"},
    {29, 20, 3, "20-node tetrahedron"},
    {30, 35, 3, "35-node tetrahedron"},
    {31, 56, 3, "56-node tetrahedron"},
};

const ElementType* find_type(long long type) {
  for (const ElementType& known : kElementTypes) {
    if (known.type == type) return &known;
  }
  return nullptr;
}

std::string unsupported_volume_element(long long type, const ElementType* known) {
  return "element type " + std::to_string(type) +
         (known != nullptr ? " (" + std::string(known->name) + ")" : std::string()) +
         " is not supported: only linear 4-node tetrahedra (type 4) are read; export first-order "
         "tetrahedra (gmsh -order 1)";
}

class MshReader {
 public:
  MshReader(std::string_view text, const std::string& label, MeshReadReport* report)
      : text_(text), label_(label), report_(report), scan_(text) {}

  TetMesh read() {
    if (report_ != nullptr) *report_ = MeshReadReport();
    read_format();
    std::string_view token;
    while (scan_.token(token)) {
      const std::size_t line = scan_.token_line();
      if (token.empty() || token.front() != '$' || token.size() < 2) {
        fail_here(line, "expected a section such as $Nodes, found '" + printable(token) + "'");
      }
      const std::string_view name = token.substr(1);
      if (name == "Nodes") {
        if (have_nodes_) fail_here(line, "second $Nodes section");
        if (version_ == 4) {
          binary_ ? read_nodes4_binary() : read_nodes4_ascii();
        } else {
          read_nodes2();
        }
        have_nodes_ = true;
        build_tag_index(line);
        expect_end("Nodes", line);
      } else if (name == "Elements") {
        if (have_elements_) fail_here(line, "second $Elements section");
        if (!have_nodes_) fail_here(line, "$Elements before $Nodes");
        if (version_ == 4) {
          binary_ ? read_elements4_binary() : read_elements4_ascii();
        } else {
          read_elements2();
        }
        have_elements_ = true;
        expect_end("Elements", line);
      } else if (name.substr(0, 3) == "End") {
        fail_here(line, "'" + printable(token) + "' without its opening section");
      } else if (name == "MeshFormat") {
        fail_here(line, "second $MeshFormat section");
      } else {
        skip_section(name, line);
      }
    }
    if (!have_nodes_) fail_end("no $Nodes section");
    if (!have_elements_) fail_end("no $Elements section");
    if (mesh_.tetrahedra.empty()) {
      fail_end("no 4-node tetrahedra (type 4) in $Elements" +
               std::string(skipped_ > 0 ? " (only points, lines or surface elements)" : ""));
    }
    if (report_ != nullptr) report_->skipped_elements = skipped_;
    mesh_detail::finish_report(mesh_, label_, report_);
    return std::move(mesh_);
  }

 private:
  // ------------------------------------------------------------------ errors and tokens

  [[noreturn]] void fail_line(std::size_t line, const std::string& cause) const {
    mesh_detail::fail_line(label_, line, cause);
  }
  // In binary files line numbers mean nothing past the header, so errors give the offset.
  [[noreturn]] void fail_here(std::size_t line, const std::string& cause) const {
    if (binary_ && past_header_) mesh_detail::fail_byte(label_, scan_.pos(), cause);
    fail_line(line, cause);
  }
  [[noreturn]] void fail_end(const std::string& cause) const {
    if (binary_) mesh_detail::fail_file(label_, cause);
    fail_line(scan_.line_number(), cause);
  }

  template <typename Describe>
  std::string_view next(const Describe& what) {
    std::string_view token;
    if (!scan_.token(token)) {
      fail_here(scan_.token_line(), "unexpected end of file, expected " + what());
    }
    return token;
  }

  template <typename Describe>
  long long next_int(const Describe& what) {
    const std::string_view token = next(what);
    long long value = 0;
    if (!mesh_detail::parse_int(token, value)) {
      fail_here(scan_.token_line(), "expected an integer for " + what() + ", found '" + printable(token) + "'");
    }
    return value;
  }

  // A count in [0, limit] that the rest of the file can hold at `min_bytes` bytes per item.
  template <typename Describe>
  unsigned long long checked_count(long long value, unsigned long long limit, std::size_t min_bytes,
                                   const Describe& what) {
    if (value < 0) {
      fail_here(scan_.token_line(), what() + " must not be negative (found " + std::to_string(value) + ")");
    }
    const auto count = static_cast<unsigned long long>(value);
    if (count > limit) {
      fail_here(scan_.token_line(),
                what() + " " + std::to_string(count) + " exceeds the limit of " + std::to_string(limit));
    }
    if (count > scan_.remaining() / min_bytes) {
      fail_here(scan_.token_line(),
                what() + " " + std::to_string(count) + " is larger than the rest of the file can hold");
    }
    return count;
  }

  template <typename Describe>
  double next_coordinate(const Describe& what) {
    const std::string_view token = next(what);
    double value = 0.0;
    if (!mesh_detail::parse_real(token, value)) {
      fail_here(scan_.token_line(), "expected a number for " + what() + ", found '" + printable(token) + "'");
    }
    if (!std::isfinite(value)) {
      fail_here(scan_.token_line(), what() + " is not finite ('" + printable(token) + "')");
    }
    return value;
  }

  void expect_end(std::string_view name, std::size_t open_line) {
    std::string_view token;
    const std::string expected = "$End" + std::string(name);
    if (!scan_.token(token)) {
      fail_end("missing " + expected + " (section $" + std::string(name) + " opened at line " +
               std::to_string(open_line) + ")");
    }
    if (token != expected) {
      fail_here(scan_.token_line(),
                "expected " + expected + ", found '" + printable(token) + "' (do the counts match the data?)");
    }
  }

  // Any other section ($Entities, $PhysicalNames, $NodeData, user sections...) is skipped up to
  // its end marker at the start of a line.
  void skip_section(std::string_view name, std::size_t open_line) {
    const std::string marker = "$End" + std::string(name);
    std::size_t from = scan_.pos();
    for (;;) {
      const std::size_t at = text_.find(marker, from);
      if (at == std::string_view::npos) {
        fail_end("missing " + marker + " (section $" + printable(name) + " opened at line " +
                 std::to_string(open_line) + ")");
      }
      const std::size_t after = at + marker.size();
      const bool line_start = at == 0 || text_[at - 1] == '\n';
      const bool token_end = after == text_.size() || mesh_detail::is_space(text_[after]);
      if (line_start && token_end) {
        std::size_t line = scan_.line_number();
        if (!binary_) {
          line += static_cast<std::size_t>(std::count(text_.begin() + static_cast<std::ptrdiff_t>(scan_.pos()),
                                                      text_.begin() + static_cast<std::ptrdiff_t>(after), '\n'));
        }
        scan_.seek(after, line);
        return;
      }
      from = at + 1;
    }
  }

  // ------------------------------------------------------------------ $MeshFormat

  void read_format() {
    std::string_view token;
    if (!scan_.token(token) || token != "$MeshFormat") {
      fail_line(scan_.token_line(), "not a gmsh MSH file (expected $MeshFormat)");
    }
    const std::string_view version = next([] { return std::string("the MSH version"); });
    const std::size_t version_line = scan_.token_line();
    double number = 0.0;
    if (!mesh_detail::parse_real(version, number)) {
      fail_line(version_line, "MSH version '" + printable(version) + "' is not a number");
    }
    if (version == "4.1") {
      version_ = 4;
    } else if (number >= 2.0 && number < 3.0) {
      version_ = 2;
    } else {
      fail_line(version_line,
                "unsupported MSH version " + printable(version) + " (supported: 4.1 ASCII or binary, 2.2 ASCII)");
    }
    const long long file_type = next_int([] { return std::string("the MSH file type"); });
    if (file_type != 0 && file_type != 1) {
      fail_line(scan_.token_line(),
                "MSH file type must be 0 (ASCII) or 1 (binary), found " + std::to_string(file_type));
    }
    binary_ = file_type == 1;
    if (binary_ && version_ == 2) {
      fail_line(version_line, "binary MSH 2 files are not supported (write MSH 4.1 or ASCII)");
    }
    const long long data_size = next_int([] { return std::string("the MSH data size"); });
    if (binary_ && data_size != 4 && data_size != 8) {
      fail_line(scan_.token_line(),
                "MSH data size (size of size_t) must be 4 or 8, found " + std::to_string(data_size));
    }
    size_bytes_ = data_size == 4 ? 4 : 8;
    if (binary_) {
      // The header line ends, then the int 1 in the writer's byte order, then a newline.
      std::string_view rest;
      scan_.line(rest);
      const std::size_t at = scan_.pos();
      if (scan_.remaining() < 4) fail_line(scan_.line_number(), "unexpected end of file in header");
      std::uint32_t one = 0;
      std::memcpy(&one, text_.data() + at, 4);
      if (one == 1) {
        swap_ = false;
      } else if (one == 0x01000000u) {
        swap_ = true;
      } else {
        fail_line(scan_.line_number(),
                  "binary MSH header lacks the integer 1 that gives the byte "
                  "order");
      }
      scan_.seek(at + 4, scan_.line_number());
    }
    std::string_view end;
    if (!scan_.token(end) || end != "$EndMeshFormat") {
      fail_line(scan_.token_line(), "expected $EndMeshFormat after the version line");
    }
    past_header_ = true;
  }

  // Binary data starts after the newline that ends the section keyword's line.
  BinaryReader binary_start() {
    std::string_view rest;
    scan_.line(rest);
    return BinaryReader(text_, scan_.pos(), swap_, label_);
  }
  void binary_done(const BinaryReader& in) { scan_.seek(in.pos(), scan_.line_number()); }

  // ------------------------------------------------------------------ nodes

  void add_node(unsigned long long tag, const double xyz[3]) {
    node_tags_.push_back(tag);
    mesh_.points.insert(mesh_.points.end(), xyz, xyz + 3);
  }

  void read_nodes4_ascii() {
    const long long blocks_raw = next_int([] { return std::string("the number of node blocks"); });
    const auto blocks = checked_count(blocks_raw, kMaxNodes, 8, [] { return std::string("number of node blocks"); });
    const long long total_raw = next_int([] { return std::string("the number of nodes"); });
    const auto total = checked_count(total_raw, kMaxNodes, 8, [] { return std::string("number of nodes"); });
    next_int([] { return std::string("the minimum node tag"); });
    next_int([] { return std::string("the maximum node tag"); });
    std::vector<unsigned long long> block_tags;
    for (unsigned long long block = 0; block < blocks; ++block) {
      const auto describe_block = [&] { return "node block " + std::to_string(block); };
      const long long dim = next_int([&] { return "the entity dimension of " + describe_block(); });
      next_int([&] { return "the entity tag of " + describe_block(); });
      const long long parametric = next_int([&] { return "the parametric flag of " + describe_block(); });
      if (dim < 0 || dim > 3) {
        fail_here(scan_.token_line(),
                  "entity dimension " + std::to_string(dim) + " of " + describe_block() + " must be 0 to 3");
      }
      if (parametric != 0 && parametric != 1) {
        fail_here(scan_.token_line(), "parametric flag of " + describe_block() + " must be 0 or 1");
      }
      const long long count_raw = next_int([&] { return "the node count of " + describe_block(); });
      const auto count = checked_count(count_raw, kMaxNodes, 8, [&] { return "node count of " + describe_block(); });
      if (node_tags_.size() + count > total) {
        fail_here(scan_.token_line(),
                  "node blocks hold more nodes than the " + std::to_string(total) + " the $Nodes header declares");
      }
      block_tags.clear();
      for (unsigned long long i = 0; i < count; ++i) {
        block_tags.push_back(read_tag([&] { return "a node tag of " + describe_block(); }));
      }
      const long long extra = parametric == 1 ? dim : 0;
      for (unsigned long long i = 0; i < count; ++i) {
        double xyz[3];
        for (int axis = 0; axis < 3; ++axis) {
          xyz[axis] = next_coordinate([&] { return "a coordinate of node " + std::to_string(block_tags[i]); });
        }
        for (long long k = 0; k < extra; ++k) {
          next_coordinate([&] { return "a parametric coordinate of node " + std::to_string(block_tags[i]); });
        }
        add_node(block_tags[i], xyz);
      }
    }
    if (node_tags_.size() != total) {
      fail_here(scan_.token_line(), "the $Nodes header declares " + std::to_string(total) +
                                        " nodes but its blocks hold " + std::to_string(node_tags_.size()));
    }
  }

  template <typename Describe>
  unsigned long long read_tag(const Describe& what) {
    const long long tag = next_int(what);
    if (tag <= 0) {
      fail_here(scan_.token_line(), what() + " must be positive (found " + std::to_string(tag) + ")");
    }
    return static_cast<unsigned long long>(tag);
  }

  void read_nodes4_binary() {
    BinaryReader in = binary_start();
    const std::size_t sz = size_bytes_;
    const auto blocks = in.read_unsigned(sz, [] { return std::string("the $Nodes header"); });
    const auto total = in.read_unsigned(sz, [] { return std::string("the $Nodes header"); });
    in.read_unsigned(sz, [] { return std::string("the $Nodes header"); });
    in.read_unsigned(sz, [] { return std::string("the $Nodes header"); });
    if (total > kMaxNodes) {
      mesh_detail::fail_byte(
          label_, in.pos(),
          "number of nodes " + std::to_string(total) + " exceeds the limit of " + std::to_string(kMaxNodes));
    }
    in.require(total, sz + 24, [] { return std::string("$Nodes"); });
    in.require(blocks, 12 + sz, [] { return std::string("$Nodes"); });
    for (unsigned long long block = 0; block < blocks; ++block) {
      const auto describe_block = [&] { return "node block " + std::to_string(block); };
      const std::int32_t dim = in.read<std::int32_t>(describe_block);
      in.read<std::int32_t>(describe_block);
      const std::int32_t parametric = in.read<std::int32_t>(describe_block);
      const auto count = in.read_unsigned(sz, describe_block);
      if (dim < 0 || dim > 3 || (parametric != 0 && parametric != 1)) {
        mesh_detail::fail_byte(label_, in.pos(),
                               describe_block() +
                                   " has an invalid entity dimension or "
                                   "parametric flag");
      }
      if (count > total - node_tags_.size()) {
        mesh_detail::fail_byte(
            label_, in.pos(),
            "node blocks hold more nodes than the " + std::to_string(total) + " the $Nodes header declares");
      }
      const std::size_t values = 3 + (parametric == 1 ? static_cast<std::size_t>(dim) : 0);
      in.require(count, sz + 8 * values, describe_block);
      const std::size_t first = node_tags_.size();
      for (unsigned long long i = 0; i < count; ++i) {
        const auto tag = in.read_unsigned(sz, describe_block);
        if (tag == 0) mesh_detail::fail_byte(label_, in.pos(), "node tag 0 (tags start at 1)");
        node_tags_.push_back(tag);
      }
      for (unsigned long long i = 0; i < count; ++i) {
        for (std::size_t k = 0; k < values; ++k) {
          const double value = in.read<double>(describe_block);
          if (k < 3) {
            if (!std::isfinite(value)) {
              mesh_detail::fail_byte(
                  label_, in.pos() - 8,
                  "a coordinate of node " + std::to_string(node_tags_[first + i]) + " is not finite");
            }
            mesh_.points.push_back(value);
          }
        }
      }
    }
    if (node_tags_.size() != total) {
      mesh_detail::fail_byte(label_, in.pos(),
                             "the $Nodes header declares " + std::to_string(total) + " nodes but its blocks hold " +
                                 std::to_string(node_tags_.size()));
    }
    binary_done(in);
  }

  void read_nodes2() {
    const long long total_raw = next_int([] { return std::string("the number of nodes"); });
    const auto total = checked_count(total_raw, kMaxNodes, 8, [] { return std::string("number of nodes"); });
    for (unsigned long long i = 0; i < total; ++i) {
      const auto tag = read_tag([&] { return "the tag of node " + std::to_string(i); });
      double xyz[3];
      for (int axis = 0; axis < 3; ++axis) {
        xyz[axis] = next_coordinate([&] { return "a coordinate of node " + std::to_string(tag); });
      }
      add_node(tag, xyz);
    }
  }

  void build_tag_index(std::size_t line) {
    if (node_tags_.empty()) fail_here(line, "$Nodes holds no nodes");
    tag_index_.resize(node_tags_.size());
    for (std::size_t i = 0; i < node_tags_.size(); ++i) {
      tag_index_[i] = {node_tags_[i], static_cast<int>(i)};
    }
    std::sort(tag_index_.begin(), tag_index_.end());
    for (std::size_t i = 1; i < tag_index_.size(); ++i) {
      if (tag_index_[i].first == tag_index_[i - 1].first) {
        fail_here(line, "node tag " + std::to_string(tag_index_[i].first) + " is defined twice in $Nodes");
      }
    }
    node_tags_.clear();
    node_tags_.shrink_to_fit();
  }

  // Index of the node with `tag`, or -1.
  int node_index(unsigned long long tag) const {
    const auto it = std::lower_bound(
        tag_index_.begin(), tag_index_.end(), tag,
        [](const std::pair<unsigned long long, int>& entry, unsigned long long key) { return entry.first < key; });
    return it != tag_index_.end() && it->first == tag ? it->second : -1;
  }

  // ------------------------------------------------------------------ elements

  // Resolves and checks one tetrahedron; `where` gives the error location.
  template <typename Fail>
  void add_tet(const unsigned long long tags[4], unsigned long long element_tag, const Fail& fail) {
    int tet[4];
    for (int k = 0; k < 4; ++k) {
      tet[k] = node_index(tags[k]);
      if (tet[k] < 0) {
        fail("element " + std::to_string(element_tag) + ": node tag " + std::to_string(tags[k]) +
             " is not defined in $Nodes");
      }
    }
    const std::size_t number = mesh_.tetrahedra.size() / 4;
    const std::string cause = mesh_detail::orient_tet(mesh_.points.data(), tet, number, report_);
    if (!cause.empty()) fail(cause + " (element " + std::to_string(element_tag) + ")");
    mesh_.tetrahedra.insert(mesh_.tetrahedra.end(), tet, tet + 4);
  }

  // The rest of the current line must be blank (after a block header read token by token).
  void finish_header_line() {
    std::string_view rest;
    const std::size_t line = scan_.line_number();
    scan_.line(rest);
    for (const char c : rest) {
      if (!mesh_detail::is_space(c)) {
        fail_line(line, "unexpected '" + printable(rest) + "' after an element block header");
      }
    }
  }

  // Next non-blank line of an element list.
  std::string_view element_line(const std::string& what) {
    std::string_view line;
    for (;;) {
      if (!scan_.line(line)) {
        fail_line(scan_.token_line(), "unexpected end of file, expected " + what);
      }
      for (const char c : line) {
        if (!mesh_detail::is_space(c)) return line;
      }
    }
  }

  void read_elements4_ascii() {
    const long long blocks_raw = next_int([] { return std::string("the number of element blocks"); });
    const auto blocks =
        checked_count(blocks_raw, kMaxElements, 8, [] { return std::string("number of element blocks"); });
    const long long total_raw = next_int([] { return std::string("the number of elements"); });
    const auto total = checked_count(total_raw, kMaxElements, 4, [] { return std::string("number of elements"); });
    next_int([] { return std::string("the minimum element tag"); });
    next_int([] { return std::string("the maximum element tag"); });
    unsigned long long seen = 0;
    for (unsigned long long block = 0; block < blocks; ++block) {
      const auto describe_block = [&] { return "element block " + std::to_string(block); };
      const long long dim = next_int([&] { return "the entity dimension of " + describe_block(); });
      next_int([&] { return "the entity tag of " + describe_block(); });
      const long long type = next_int([&] { return "the element type of " + describe_block(); });
      const std::size_t header_line = scan_.token_line();
      const long long count_raw = next_int([&] { return "the element count of " + describe_block(); });
      const auto count =
          checked_count(count_raw, kMaxElements, 4, [&] { return "element count of " + describe_block(); });
      if (dim < 0 || dim > 3) {
        fail_line(header_line,
                  "entity dimension " + std::to_string(dim) + " of " + describe_block() + " must be 0 to 3");
      }
      if (count > total - seen) {
        fail_line(header_line, "element blocks hold more elements than the " + std::to_string(total) +
                                   " the $Elements header declares");
      }
      seen += count;
      const ElementType* known = find_type(type);
      const bool keep = type == 4;
      if (!keep && (dim == 3 || (known != nullptr && known->dimension == 3))) {
        fail_line(header_line, unsupported_volume_element(type, known));
      }
      finish_header_line();
      for (unsigned long long i = 0; i < count; ++i) {
        const std::string_view line = element_line("element " + std::to_string(i) + " of " + describe_block());
        if (!keep) {
          ++skipped_;
          continue;
        }
        read_tet_line(line, 0);
      }
    }
    if (seen != total) {
      fail_line(scan_.line_number(), "the $Elements header declares " + std::to_string(total) +
                                         " elements but its blocks hold " + std::to_string(seen));
    }
  }

  // "tag [type ntags tags...] n1 n2 n3 n4" with `skip` fields between the tag and the nodes
  // (MSH 2 passes them already checked).
  void read_tet_line(std::string_view text, std::size_t skip) {
    const std::size_t line = scan_.token_line();
    Scanner fields(text);
    std::string_view token;
    long long values[5];
    std::size_t count = 0;
    std::size_t index = 0;
    while (fields.token(token)) {
      if (index == 0 || index > skip) {
        if (count == 5) fail_line(line, "a 4-node tetrahedron line has more than 4 node tags");
        if (!mesh_detail::parse_int(token, values[count]) || values[count] <= 0) {
          fail_line(line, "expected a positive integer tag, found '" + printable(token) + "'");
        }
        ++count;
      }
      ++index;
    }
    if (count != 5) {
      fail_line(line, "a 4-node tetrahedron line needs an element tag and 4 node tags, found " + std::to_string(count) +
                          " values");
    }
    const unsigned long long tags[4] = {
        static_cast<unsigned long long>(values[1]), static_cast<unsigned long long>(values[2]),
        static_cast<unsigned long long>(values[3]), static_cast<unsigned long long>(values[4])};
    add_tet(tags, static_cast<unsigned long long>(values[0]),
            [&](const std::string& cause) { fail_line(line, cause); });
  }

  void read_elements4_binary() {
    BinaryReader in = binary_start();
    const std::size_t sz = size_bytes_;
    const auto blocks = in.read_unsigned(sz, [] { return std::string("the $Elements header"); });
    const auto total = in.read_unsigned(sz, [] { return std::string("the $Elements header"); });
    in.read_unsigned(sz, [] { return std::string("the $Elements header"); });
    in.read_unsigned(sz, [] { return std::string("the $Elements header"); });
    if (total > kMaxElements) {
      mesh_detail::fail_byte(
          label_, in.pos(),
          "number of elements " + std::to_string(total) + " exceeds the limit of " + std::to_string(kMaxElements));
    }
    in.require(total, 2 * sz, [] { return std::string("$Elements"); });
    in.require(blocks, 12 + sz, [] { return std::string("$Elements"); });
    unsigned long long seen = 0;
    for (unsigned long long block = 0; block < blocks; ++block) {
      const auto describe_block = [&] { return "element block " + std::to_string(block); };
      const std::size_t header_at = in.pos();
      const std::int32_t dim = in.read<std::int32_t>(describe_block);
      in.read<std::int32_t>(describe_block);
      const std::int32_t type = in.read<std::int32_t>(describe_block);
      const auto count = in.read_unsigned(sz, describe_block);
      if (dim < 0 || dim > 3) {
        mesh_detail::fail_byte(label_, header_at, describe_block() + " has entity dimension " + std::to_string(dim));
      }
      if (count > total - seen) {
        mesh_detail::fail_byte(
            label_, header_at,
            "element blocks hold more elements than the " + std::to_string(total) + " the $Elements header declares");
      }
      seen += count;
      const ElementType* known = find_type(type);
      if (type != 4 && (dim == 3 || (known != nullptr && known->dimension == 3))) {
        mesh_detail::fail_byte(label_, header_at, unsupported_volume_element(type, known));
      }
      if (known == nullptr) {
        mesh_detail::fail_byte(label_, header_at,
                               "element type " + std::to_string(type) +
                                   " is unknown, so its block cannot be "
                                   "skipped in a binary file");
      }
      const std::size_t per_element = sz * (1 + static_cast<std::size_t>(known->nodes));
      in.require(count, per_element, describe_block);
      if (type != 4) {
        in.skip(static_cast<std::size_t>(count) * per_element);
        skipped_ += static_cast<int>(count);  // count <= kMaxElements in total
        continue;
      }
      for (unsigned long long i = 0; i < count; ++i) {
        const std::size_t at = in.pos();
        const auto tag = in.read_unsigned(sz, describe_block);
        unsigned long long tags[4];
        for (auto& node : tags) node = in.read_unsigned(sz, describe_block);
        add_tet(tags, tag, [&](const std::string& cause) { mesh_detail::fail_byte(label_, at, cause); });
      }
    }
    if (seen != total) {
      mesh_detail::fail_byte(label_, in.pos(),
                             "the $Elements header declares " + std::to_string(total) +
                                 " elements but its blocks hold " + std::to_string(seen));
    }
    binary_done(in);
  }

  void read_elements2() {
    const long long total_raw = next_int([] { return std::string("the number of elements"); });
    const auto total = checked_count(total_raw, kMaxElements, 4, [] { return std::string("number of elements"); });
    finish_header_line();
    for (unsigned long long i = 0; i < total; ++i) {
      const std::string_view text = element_line("element " + std::to_string(i));
      const std::size_t line = scan_.token_line();
      Scanner fields(text);
      std::string_view token;
      long long head[3] = {0, 0, 0};
      for (long long& value : head) {
        if (!fields.token(token) || !mesh_detail::parse_int(token, value)) {
          fail_line(line, "expected 'tag type tag-count ...' for an element, found '" + printable(text) + "'");
        }
      }
      const long long type = head[1];
      const long long tag_count = head[2];
      const ElementType* known = find_type(type);
      if (known == nullptr) {
        fail_line(line, "element type " + std::to_string(type) + " is unknown");
      }
      if (type != 4) {
        if (known->dimension == 3) fail_line(line, unsupported_volume_element(type, known));
        ++skipped_;
        continue;
      }
      if (tag_count < 0 || tag_count > 1000) {
        fail_line(line, "element tag count " + std::to_string(tag_count) + " is not plausible");
      }
      read_tet_line(text, 2 + static_cast<std::size_t>(tag_count));
    }
  }

  std::string_view text_;
  const std::string& label_;
  MeshReadReport* report_;
  Scanner scan_;
  TetMesh mesh_;
  int version_ = 4;
  bool binary_ = false;
  bool swap_ = false;
  bool past_header_ = false;
  std::size_t size_bytes_ = 8;
  bool have_nodes_ = false;
  bool have_elements_ = false;
  int skipped_ = 0;
  std::vector<unsigned long long> node_tags_;
  std::vector<std::pair<unsigned long long, int>> tag_index_;
};

}  // namespace

TetMesh parse_msh(std::string_view text, const std::string& file_label, MeshReadReport* report) {
  return MshReader(text, file_label, report).read();
}

void write_msh(const TetMesh& mesh, std::ostream& out) {
  mesh_detail::check_writable(mesh, "write_msh");
  const std::size_t points = mesh.points.size() / 3;
  const std::size_t tets = mesh.tetrahedra.size() / 4;
  out << "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n";
  out << "$Nodes\n1 " << points << " 1 " << points << "\n3 1 0 " << points << '\n';
  for (std::size_t i = 0; i < points; ++i) out << i + 1 << '\n';
  std::string line;
  for (std::size_t i = 0; i < points; ++i) {
    line.clear();
    for (std::size_t axis = 0; axis < 3; ++axis) {
      if (axis > 0) line.push_back(' ');
      line += mesh_detail::format_double(mesh.points[3 * i + axis]);
    }
    out << line << '\n';
  }
  out << "$EndNodes\n$Elements\n1 " << tets << " 1 " << tets << "\n3 1 4 " << tets << '\n';
  for (std::size_t t = 0; t < tets; ++t) {
    out << t + 1;
    for (std::size_t k = 0; k < 4; ++k) out << ' ' << mesh.tetrahedra[4 * t + k] + 1;
    out << '\n';
  }
  out << "$EndElements\n";
}

}  // namespace pliant::host
