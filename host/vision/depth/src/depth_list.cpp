#include "pliant/vision/depth_list.hpp"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <sstream>

#include "pliant/vision/depth_image.hpp"

namespace pliant::vision {
namespace {

bool blank(char c) { return c == ' ' || c == '\t'; }

// Quotes a field for an error message, with control bytes escaped and long text cut.
std::string printable(std::string_view text) {
  std::string out;
  for (const char c : text.substr(0, 40)) {
    const auto byte = static_cast<unsigned char>(c);
    if (byte < 0x20 || byte == 0x7f) {
      static const char kHex[] = "0123456789abcdef";
      out += "\\x";
      out += kHex[byte >> 4];
      out += kHex[byte & 0xf];
    } else {
      out += c;
    }
  }
  if (text.size() > 40) out += "...";
  return "'" + out + "'";
}

// The first line of `text` without its line end (LF or CRLF); `text` keeps what follows.
std::string_view take_line(std::string_view& text) {
  const std::size_t end = text.find('\n');
  std::string_view line = text.substr(0, end);
  text.remove_prefix(end == std::string_view::npos ? text.size() : end + 1);
  if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
  return line;
}

constexpr std::string_view kRecordedHeader = "index,t,file,depth_scale_m,fx,fy,cx,cy";

// A decimal number (finite unless allow_nan and the text is "nan").
bool parse_number(std::string_view field, bool allow_nan, double& out) {
  const std::string text(field);
  if (allow_nan && (text == "nan" || text == "NaN" || text == "-nan")) {
    out = std::numeric_limits<double>::quiet_NaN();
    return true;
  }
  if (text.empty() || blank(text.front())) return false;
  char* stop = nullptr;
  errno = 0;
  out = std::strtod(text.c_str(), &stop);
  return stop == text.c_str() + text.size() && errno != ERANGE && std::isfinite(out);
}

void check_file_name(std::string_view name, const std::string& where) {
  if (name.empty()) throw DepthError(where + "empty file name");
  for (const char c : name) {
    const auto byte = static_cast<unsigned char>(c);
    if (byte < 0x20 || byte == 0x7f) throw DepthError(where + "control character in file name " + printable(name));
  }
}

void check_follows(const std::vector<DepthListEntry>& entries, double t, std::string_view field,
                   const std::string& where) {
  if (!entries.empty() && !(t > entries.back().t_s)) {
    throw DepthError(where + "timestamp " + printable(field) + " does not follow the previous one");
  }
}

// `pliant record`'s depth_frames.csv, after its header line.
std::vector<DepthListEntry> parse_recorded_frames(std::string_view text, const std::string& label) {
  std::vector<DepthListEntry> entries;
  std::size_t line_number = 1;
  while (!text.empty()) {
    ++line_number;
    const std::string_view line = take_line(text);
    if (line.empty()) continue;
    const std::string where = label + ":" + std::to_string(line_number) + ": ";
    std::vector<std::string_view> fields;
    for (std::size_t start = 0;;) {
      const std::size_t comma = line.find(',', start);
      fields.push_back(line.substr(start, comma == std::string_view::npos ? std::string_view::npos : comma - start));
      if (comma == std::string_view::npos) break;
      start = comma + 1;
    }
    if (fields.size() != 8) {
      throw DepthError(where + "expected 8 fields (" + std::string(kRecordedHeader) + "), found " +
                       std::to_string(fields.size()));
    }
    double index = 0;
    if (!parse_number(fields[0], false, index) || index < 0 || index != std::floor(index)) {
      throw DepthError(where + "index " + printable(fields[0]) + " is not a whole number");
    }
    DepthListEntry entry;
    if (!parse_number(fields[1], false, entry.t_s))
      throw DepthError(where + "timestamp " + printable(fields[1]) + " is not a number");
    check_follows(entries, entry.t_s, fields[1], where);
    check_file_name(fields[2], where);
    entry.path = std::string(fields[2]);
    if (!parse_number(fields[3], false, entry.depth_scale_m) || !(entry.depth_scale_m > 0)) {
      throw DepthError(where + "depth_scale_m " + printable(fields[3]) + " is not a positive number");
    }
    double* intrinsics[] = {&entry.fx, &entry.fy, &entry.cx, &entry.cy};
    static const char* const kNames[] = {"fx", "fy", "cx", "cy"};
    for (std::size_t k = 0; k < 4; ++k) {
      if (!parse_number(fields[4 + k], true, *intrinsics[k])) {
        throw DepthError(where + kNames[k] + " " + printable(fields[4 + k]) + " is neither a number nor nan");
      }
    }
    entries.push_back(std::move(entry));
  }
  if (entries.empty()) throw DepthError(label + ": no depth frame listed");
  return entries;
}

}  // namespace

std::vector<DepthListEntry> parse_depth_list(std::string_view text, const std::string& label) {
  {
    std::string_view rest = text;
    if (take_line(rest) == kRecordedHeader) return parse_recorded_frames(rest, label);
  }
  std::vector<DepthListEntry> entries;
  std::size_t line_number = 0;
  while (!text.empty()) {
    ++line_number;
    const std::string_view line = take_line(text);
    const std::string where = label + ":" + std::to_string(line_number) + ": ";
    std::vector<std::string_view> fields;
    std::size_t i = 0;
    while (i < line.size()) {
      while (i < line.size() && blank(line[i])) ++i;
      if (i == line.size()) break;
      const std::size_t start = i;
      while (i < line.size() && !blank(line[i])) ++i;
      fields.push_back(line.substr(start, i - start));
    }
    if (fields.empty() || fields.front().front() == '#') continue;
    if (fields.size() != 2) {
      throw DepthError(where + "expected 'timestamp filename', found " + std::to_string(fields.size()) + " field(s)");
    }
    const std::string stamp(fields[0]);
    char* stop = nullptr;
    errno = 0;
    const double t = std::strtod(stamp.c_str(), &stop);
    if (stop != stamp.c_str() + stamp.size() || errno == ERANGE || !std::isfinite(t)) {
      throw DepthError(where + "timestamp " + printable(fields[0]) + " is not a number");
    }
    check_file_name(fields[1], where);
    check_follows(entries, t, fields[0], where);
    DepthListEntry entry;
    entry.t_s = t;
    entry.path = std::string(fields[1]);
    entries.push_back(std::move(entry));
  }
  if (entries.empty()) throw DepthError(label + ": no depth frame listed");
  return entries;
}

std::vector<DepthListEntry> read_depth_list(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw DepthError(path + ": cannot open");
  std::ostringstream buffer;
  buffer << in.rdbuf();
  if (in.bad()) throw DepthError(path + ": read error");
  const std::filesystem::path list(path);
  std::vector<DepthListEntry> entries = parse_depth_list(buffer.str(), list.filename().string());
  for (DepthListEntry& entry : entries) {
    const std::filesystem::path file(entry.path);
    if (file.is_relative()) entry.path = (list.parent_path() / file).string();
  }
  return entries;
}

}  // namespace pliant::vision
