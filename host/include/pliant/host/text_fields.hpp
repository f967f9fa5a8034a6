// Text helpers of the host's file readers and writers (recording v1, the dataset importers): line
// splitting, strict locale-independent number parsing and shortest round-trip formatting,
// one-line error messages that throw RecordingError. Part of pliant::recording; installed, but in
// namespace detail: readers of other formats may use it, and it may change between versions.
#pragma once

#include <charconv>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include "pliant/host/recording.hpp"

namespace pliant::host::detail {

/// Upper bound on particles.count and on mesh point counts.
inline constexpr long long kMaxParticles = 10'000'000;
/// Upper bound on frames * particles * dimension stored positions (2 GiB of doubles).
inline constexpr std::size_t kMaxPositionValues = std::size_t{1} << 28;

/// `text` made safe to quote inside a one-line message: control bytes become '?', and text
/// longer than `max_chars` is cut and marked with "...".
inline std::string printable(std::string_view text, std::size_t max_chars = 40) {
  std::string out;
  const std::size_t n = text.size() < max_chars ? text.size() : max_chars;
  out.reserve(n + 3);
  for (std::size_t i = 0; i < n; ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    out.push_back(c < 0x20 || c == 0x7f ? '?' : text[i]);
  }
  if (text.size() > max_chars) out += "...";
  return out;
}

/// Shortest text that reads back to exactly `value` ("nan" for any NaN).
inline std::string format_double(double value) {
  if (std::isnan(value)) return "nan";
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
  return std::string(buffer, result.ptr);
}

[[noreturn]] inline void fail_at(const std::string& file_label, std::size_t line, const std::string& cause) {
  throw RecordingError(file_label + ":" + std::to_string(line) + ": " + cause);
}

enum class NumberStatus { ok, not_a_number, out_of_range };

/// Parses the whole field as a decimal floating-point number (std::from_chars, so no locale,
/// no leading whitespace or '+'). Accepts nan/inf spellings; callers decide whether those are
/// allowed.
inline NumberStatus parse_double(std::string_view field, double& value) {
  if (field.empty()) return NumberStatus::not_a_number;
  const char* end = field.data() + field.size();
  const auto result = std::from_chars(field.data(), end, value);
  if (result.ec == std::errc::result_out_of_range) return NumberStatus::out_of_range;
  if (result.ec != std::errc() || result.ptr != end) return NumberStatus::not_a_number;
  return NumberStatus::ok;
}

/// Parses the whole field as a decimal integer.
inline NumberStatus parse_integer(std::string_view field, long long& value) {
  if (field.empty()) return NumberStatus::not_a_number;
  const char* end = field.data() + field.size();
  const auto result = std::from_chars(field.data(), end, value);
  if (result.ec == std::errc::result_out_of_range) return NumberStatus::out_of_range;
  if (result.ec != std::errc() || result.ptr != end) return NumberStatus::not_a_number;
  return NumberStatus::ok;
}

inline bool equals_ignoring_case(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    char x = a[i];
    char y = b[i];
    if (x >= 'A' && x <= 'Z') x = static_cast<char>(x - 'A' + 'a');
    if (y >= 'A' && y <= 'Z') y = static_cast<char>(y - 'A' + 'a');
    if (x != y) return false;
  }
  return true;
}

/// Splits text into lines: strips a leading UTF-8 BOM, accepts "\n" or "\r\n" endings and a
/// missing final newline. Line numbers start at 1.
class LineReader {
 public:
  explicit LineReader(std::string_view text) : text_(text) {
    if (text_.substr(0, 3) == "\xEF\xBB\xBF") text_.remove_prefix(3);
  }
  /// Next line without its ending; false at end of text.
  bool next(std::string_view& line) {
    if (pos_ >= text_.size()) return false;
    const std::size_t newline = text_.find('\n', pos_);
    const std::size_t stop = newline == std::string_view::npos ? text_.size() : newline;
    line = text_.substr(pos_, stop - pos_);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    pos_ = newline == std::string_view::npos ? text_.size() : newline + 1;
    ++number_;
    return true;
  }
  std::size_t line_number() const { return number_; }  ///< number of the last line returned
  std::size_t offset() const { return pos_; }          ///< byte offset after the last line
  std::string_view text() const { return text_; }

 private:
  std::string_view text_;
  std::size_t pos_ = 0;
  std::size_t number_ = 0;
};

inline void split_fields(std::string_view line, char separator, std::vector<std::string_view>& fields) {
  fields.clear();
  std::size_t start = 0;
  for (;;) {
    const std::size_t stop = line.find(separator, start);
    if (stop == std::string_view::npos) {
      fields.push_back(line.substr(start));
      return;
    }
    fields.push_back(line.substr(start, stop - start));
    start = stop + 1;
  }
}

/// Why `path` is not an acceptable "files" entry (relative, '/'-separated, no "..", no
/// control characters), or nullptr when it is acceptable.
inline const char* relative_path_problem(std::string_view path) {
  if (path.empty()) return "path is empty";
  if (path.front() == '/') return "path must be relative to the recording directory";
  for (const char c : path) {
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) {
      return "path contains a control character";
    }
    if (c == '\\') return "path must use '/' as separator";
  }
  if (path.back() == '/') return "path must name a file, not a directory";
  std::size_t start = 0;
  for (;;) {
    const std::size_t stop = path.find('/', start);
    const std::string_view part =
        path.substr(start, stop == std::string_view::npos ? std::string_view::npos : stop - start);
    if (part == "..") return "path must not contain '..'";
    if (stop == std::string_view::npos) return nullptr;
    start = stop + 1;
  }
}

}  // namespace pliant::host::detail
