#include "pliant/vision/depth_list.hpp"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
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

}  // namespace

std::vector<DepthListEntry> parse_depth_list(std::string_view text, const std::string& label) {
  std::vector<DepthListEntry> entries;
  std::size_t line_number = 0;
  while (!text.empty()) {
    ++line_number;
    const std::size_t end = text.find('\n');
    std::string_view line = text.substr(0, end);
    text.remove_prefix(end == std::string_view::npos ? text.size() : end + 1);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
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
    for (const char c : fields[1]) {
      const auto byte = static_cast<unsigned char>(c);
      if (byte < 0x20 || byte == 0x7f) throw DepthError(where + "control character in file name " + printable(fields[1]));
    }
    if (!entries.empty() && !(t > entries.back().t_s)) {
      throw DepthError(where + "timestamp " + printable(fields[0]) + " does not follow the previous one");
    }
    entries.push_back({t, std::string(fields[1])});
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
