#include "refine_control_points.hpp"

#include <charconv>
#include <cmath>
#include <fstream>
#include <system_error>

#include "exit_status.hpp"

namespace pliant::cli {
namespace {

bool all_digits(const std::string& text) {
  if (text.empty()) return false;
  for (char c : text) {
    if (c < '0' || c > '9') return false;
  }
  return true;
}

// Three numbers separated by commas and/or blanks, nothing else.
bool parse_point(const std::string& line, Eigen::Vector3d& point) {
  const char* at = line.data();
  const char* const end = line.data() + line.size();
  auto skip_separators = [&](bool allow_comma) {
    bool comma = false;
    while (at < end && (*at == ' ' || *at == '\t' || *at == '\r' || (allow_comma && !comma && *at == ','))) {
      comma = comma || *at == ',';
      ++at;
    }
  };
  for (int k = 0; k < 3; ++k) {
    skip_separators(k > 0);
    double value = 0;
    const auto result = std::from_chars(at, end, value);
    if (result.ec != std::errc() || !std::isfinite(value)) return false;
    point(k) = value;
    at = result.ptr;
  }
  skip_separators(false);
  return at == end;
}

}  // namespace

ControlPointSource parse_control_points(const std::string& value) {
  ControlPointSource source;
  if (value == "auto") {
    source.automatic = true;
    return source;
  }
  if (all_digits(value)) {
    if (value.size() > 3 || std::stoi(value) < 1 || std::stoi(value) > kMaxControlPoints) {
      throw UsageError("--control-points must be between 1 and " + std::to_string(kMaxControlPoints) + " (got " +
                       value + ")");
    }
    source.count = std::stoi(value);
    return source;
  }
  std::ifstream in(value);
  if (!in) throw UsageError("--control-points: cannot read " + value + " (neither a count nor a readable file)");
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    Eigen::Vector3d point = Eigen::Vector3d::Zero();
    if (!parse_point(line, point)) {
      throw UsageError(value + ":" + std::to_string(number) + ": expected three finite numbers x,y,z (metres)");
    }
    if (static_cast<int>(source.points_m.size()) == kMaxControlPoints) {
      throw UsageError(value + ": more than " + std::to_string(kMaxControlPoints) + " control points");
    }
    source.points_m.push_back(point);
  }
  if (source.points_m.empty()) throw UsageError(value + ": no control points");
  return source;
}

}  // namespace pliant::cli
