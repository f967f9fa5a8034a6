// Internal helpers shared by the mesh and surface readers: one-line errors, strict number
// parsing, a whitespace tokenizer that tracks lines, a bounds-checked binary reader, and the
// per-tetrahedron checks. Not installed.
#pragma once

#include <charconv>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <system_error>

#include "pliant/host/fem/mesh_io.hpp"

namespace pliant::host::mesh_detail {

/// `text` made safe to quote inside a one-line message (control bytes become '?', long text is
/// cut and marked with "...").
inline std::string printable(std::string_view text, std::size_t max_chars = 40) {
  std::string out;
  const std::size_t n = text.size() < max_chars ? text.size() : max_chars;
  for (std::size_t i = 0; i < n; ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    out.push_back(c < 0x20 || c >= 0x7f ? '?' : text[i]);
  }
  if (text.size() > max_chars) out += "...";
  return out;
}

[[noreturn]] inline void fail_line(const std::string& label, std::size_t line, const std::string& cause) {
  throw MeshError(label + ":" + std::to_string(line) + ": " + cause);
}

[[noreturn]] inline void fail_byte(const std::string& label, std::size_t offset, const std::string& cause) {
  throw MeshError(label + ": byte " + std::to_string(offset) + ": " + cause);
}

[[noreturn]] inline void fail_file(const std::string& label, const std::string& cause) {
  throw MeshError(label + ": " + cause);
}

/// Whole token as a decimal floating-point number (no locale; a leading '+' is accepted).
/// nan/inf spellings parse; callers reject them where they matter.
inline bool parse_real(std::string_view token, double& value) {
  if (!token.empty() && token.front() == '+') token.remove_prefix(1);
  if (token.empty()) return false;
  const char* end = token.data() + token.size();
  const auto result = std::from_chars(token.data(), end, value);
  return result.ec == std::errc() && result.ptr == end;
}

/// Whole token as a decimal integer that fits a long long (a leading '+' is accepted).
inline bool parse_int(std::string_view token, long long& value) {
  if (!token.empty() && token.front() == '+') token.remove_prefix(1);
  if (token.empty()) return false;
  const char* end = token.data() + token.size();
  const auto result = std::from_chars(token.data(), end, value);
  return result.ec == std::errc() && result.ptr == end;
}

inline bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\v' || c == '\f'; }

inline char lower(char c) { return c >= 'A' && c <= 'Z' ? static_cast<char>(c - 'A' + 'a') : c; }

inline bool iequals(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (lower(a[i]) != lower(b[i])) return false;
  }
  return true;
}

/// Whitespace-separated tokens and whole lines over a text, with 1-based line numbers.
class Scanner {
 public:
  explicit Scanner(std::string_view text, std::size_t pos = 0, std::size_t line = 1)
      : text_(text), pos_(pos), line_(line), token_line_(line) {}

  /// Next token; false at the end of the text. token_line() is its line.
  bool token(std::string_view& out) {
    while (pos_ < text_.size() && is_space(text_[pos_])) {
      if (text_[pos_] == '\n') ++line_;
      ++pos_;
    }
    token_line_ = line_;
    if (pos_ >= text_.size()) return false;
    const std::size_t start = pos_;
    while (pos_ < text_.size() && !is_space(text_[pos_])) ++pos_;
    out = text_.substr(start, pos_ - start);
    return true;
  }

  /// The rest of the current line (without "\n" or "\r\n"); moves to the next line. False at the
  /// end of the text. token_line() is the line returned.
  bool line(std::string_view& out) {
    token_line_ = line_;
    if (pos_ >= text_.size()) return false;
    const std::size_t newline = text_.find('\n', pos_);
    const std::size_t stop = newline == std::string_view::npos ? text_.size() : newline;
    out = text_.substr(pos_, stop - pos_);
    if (!out.empty() && out.back() == '\r') out.remove_suffix(1);
    if (newline == std::string_view::npos) {
      pos_ = text_.size();
    } else {
      pos_ = newline + 1;
      ++line_;
    }
    return true;
  }

  std::size_t token_line() const { return token_line_; }
  std::size_t line_number() const { return line_; }
  std::size_t pos() const { return pos_; }
  std::size_t remaining() const { return text_.size() - pos_; }
  std::string_view text() const { return text_; }
  void seek(std::size_t pos, std::size_t line) {
    pos_ = pos;
    line_ = line;
  }

 private:
  std::string_view text_;
  std::size_t pos_;
  std::size_t line_;
  std::size_t token_line_;
};

/// Bounds-checked reads of fixed-size binary values in either byte order.
class BinaryReader {
 public:
  BinaryReader(std::string_view data, std::size_t pos, bool swap, const std::string& label)
      : data_(data), pos_(pos), swap_(swap), label_(label) {}

  std::size_t pos() const { return pos_; }
  std::size_t remaining() const { return data_.size() - pos_; }
  void seek(std::size_t pos) { pos_ = pos; }

  /// Fails (naming `what`) unless `count` items of `bytes_each` bytes fit in the rest of the data.
  template <typename Describe>
  void require(unsigned long long count, std::size_t bytes_each, const Describe& what) const {
    if (bytes_each != 0 && count > remaining() / bytes_each) {
      fail_byte(label_, pos_,
                "unexpected end of file in " + what() + " (" + std::to_string(count) + " items of " +
                    std::to_string(bytes_each) + " bytes do not fit)");
    }
  }

  template <typename T, typename Describe>
  T read(const Describe& what) {
    static_assert(sizeof(T) <= 8, "scalar types only");
    if (remaining() < sizeof(T)) {
      fail_byte(label_, pos_, "unexpected end of file in " + what());
    }
    unsigned char bytes[sizeof(T)];
    std::memcpy(bytes, data_.data() + pos_, sizeof(T));
    if (swap_) {
      for (std::size_t i = 0; i < sizeof(T) / 2; ++i) {
        const unsigned char t = bytes[i];
        bytes[i] = bytes[sizeof(T) - 1 - i];
        bytes[sizeof(T) - 1 - i] = t;
      }
    }
    T value;
    std::memcpy(&value, bytes, sizeof(T));
    pos_ += sizeof(T);
    return value;
  }

  /// An unsigned integer stored in `bytes` (4 or 8) bytes.
  template <typename Describe>
  unsigned long long read_unsigned(std::size_t bytes, const Describe& what) {
    if (bytes == 4) return read<std::uint32_t>(what);
    return read<std::uint64_t>(what);
  }

  void skip(std::size_t bytes) { pos_ += bytes; }  // callers checked with require()

 private:
  std::string_view data_;
  std::size_t pos_;
  bool swap_;
  const std::string& label_;
};

inline bool host_is_little_endian() {
  const std::uint16_t probe = 1;
  unsigned char first = 0;
  std::memcpy(&first, &probe, 1);
  return first == 1;
}

// ------------------------------------------------------------------------------------------
// Tetrahedron checks (mesh_check.cpp)

enum class TetShape { positive, negative, degenerate, repeated_point };

/// Classifies tetrahedron `tet` (four valid indices into `points`, 3 doubles each).
TetShape classify_tet(const double* points, const int* tet);

/// Classifies and, when negative, swaps the last two indices. Returns a non-empty cause for a
/// degenerate tetrahedron (the caller adds file and line), else "" and counts a swap in `report`.
std::string orient_tet(const double* points, int* tet, std::size_t tet_number, MeshReadReport* report);

/// Counts unused points into `report` (with one warning naming `label`) and fails when the mesh
/// has no tetrahedra.
void finish_report(const TetMesh& mesh, const std::string& label, MeshReadReport* report);

/// Throws MeshError naming `writer` unless the arrays are whole entries, finite, and every
/// index is in range (what the writers need; orientation is not checked).
void check_writable(const TetMesh& mesh, const char* writer);

/// Shortest text that reads back to exactly `value` ("nan"/"inf"/"-inf" for those).
inline std::string format_double(double value) {
  if (std::isnan(value)) return "nan";
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
  return std::string(buffer, result.ptr);
}

}  // namespace pliant::host::mesh_detail
