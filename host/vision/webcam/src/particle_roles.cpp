// Support and driven particles: parsing the options and detecting them from the motion.
#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <map>
#include <set>
#include <stdexcept>
#include <string>

#include "pliant/vision/webcam_error.hpp"
#include "pliant/vision/webcam_roles.hpp"

namespace pliant::vision::webcam {
namespace {

constexpr double kLeastMotionPx = 0.5;

bool parse_int(const std::string& text, long& out) {
  if (text.empty() || text.size() > 9) return false;
  char* end = nullptr;
  errno = 0;
  const long value = std::strtol(text.c_str(), &end, 10);
  if (errno != 0 || end != text.c_str() + text.size() || value < 0) return false;
  out = value;
  return true;
}

bool parse_number(const std::string& text, double& out) {
  if (text.empty() || text.size() > 32) return false;
  char* end = nullptr;
  errno = 0;
  const double value = std::strtod(text.c_str(), &end);
  if (errno != 0 || end != text.c_str() + text.size() || !std::isfinite(value)) return false;
  out = value;
  return true;
}

std::vector<std::string> split(const std::string& text) {
  std::vector<std::string> parts;
  std::size_t start = 0;
  for (;;) {
    const std::size_t at = text.find(',', start);
    parts.push_back(text.substr(start, at == std::string::npos ? std::string::npos : at - start));
    if (at == std::string::npos) return parts;
    start = at + 1;
  }
}

void check_id(int id, int count, const char* option) {
  if (id < 0 || id >= count) {
    throw InputError(std::string(option) + ": particle " + std::to_string(id) + " out of range 0.." +
                     std::to_string(count - 1));
  }
}

}  // namespace

const char* grid_side_name(GridSide side) {
  switch (side) {
    case GridSide::top: return "top";
    case GridSide::bottom: return "bottom";
    case GridSide::left: return "left";
    case GridSide::right: return "right";
  }
  return "unknown";
}

SupportSpec parse_support(const std::string& text) {
  SupportSpec spec;
  if (text == "auto") return spec;
  if (text == "none") {
    spec.kind = SupportSpec::Kind::none;
    return spec;
  }
  for (GridSide side : {GridSide::top, GridSide::bottom, GridSide::left, GridSide::right}) {
    if (text == grid_side_name(side)) {
      spec.kind = SupportSpec::Kind::side;
      spec.side = side;
      return spec;
    }
  }
  spec.kind = SupportSpec::Kind::ids;
  for (const std::string& part : split(text)) {
    long id = 0;
    if (!parse_int(part, id)) {
      throw InputError("--support: expected auto, none, top, bottom, left, right or particle ids (0,1,2), found '" +
                       text + "'");
    }
    spec.ids.push_back(static_cast<int>(id));
  }
  return spec;
}

DrivenSpec parse_driven(const std::string& text) {
  DrivenSpec spec;
  if (text == "auto") return spec;
  const std::vector<std::string> parts = split(text);
  long id = 0;
  if (parts.size() == 1 && parse_int(parts[0], id)) {
    spec.kind = DrivenSpec::Kind::id;
    spec.id = static_cast<int>(id);
    return spec;
  }
  if (parts.size() == 2 && parse_number(parts[0], spec.point.x) && parse_number(parts[1], spec.point.y)) {
    spec.kind = DrivenSpec::Kind::point;
    return spec;
  }
  throw InputError("--driven: expected auto, a particle id or X,Y pixels in the first frame, found '" + text + "'");
}

std::vector<int> grid_side_particles(const ParticleGrid& grid, GridSide side) {
  // Outermost particle per column (top/bottom) or per row (left/right).
  std::map<int, int> outermost;
  for (int i = 0; i < grid.size(); ++i) {
    const std::size_t k = static_cast<std::size_t>(i);
    const bool by_column = side == GridSide::top || side == GridSide::bottom;
    const int line = by_column ? grid.col[k] : grid.row[k];
    const int depth = by_column ? grid.row[k] : grid.col[k];
    const auto it = outermost.find(line);
    if (it == outermost.end()) {
      outermost[line] = i;
      continue;
    }
    const std::size_t held = static_cast<std::size_t>(it->second);
    const int held_depth = by_column ? grid.row[held] : grid.col[held];
    const bool further = side == GridSide::top || side == GridSide::left ? depth < held_depth : depth > held_depth;
    if (further) it->second = i;
  }
  std::vector<int> ids;
  for (const auto& entry : outermost) ids.push_back(entry.second);
  std::sort(ids.begin(), ids.end());
  return ids;
}

ParticleRoles choose_roles(const ParticleGrid& grid, const std::vector<double>& motion_px, const SupportSpec& support,
                           const DrivenSpec& driven) {
  const int n = grid.size();
  if (static_cast<int>(motion_px.size()) != n) throw std::invalid_argument("choose_roles: motion size mismatch");
  ParticleRoles roles;
  const double largest = motion_px.empty() ? 0.0 : *std::max_element(motion_px.begin(), motion_px.end());
  const bool detecting = support.kind == SupportSpec::Kind::detect || driven.kind == DrivenSpec::Kind::detect;
  if (detecting && !(largest >= kLeastMotionPx)) {
    char text[64];
    std::snprintf(text, sizeof text, "%.2f", largest);
    throw InputError(std::string("nothing moved (largest particle motion ") + text +
                     " px): cannot detect the support and the driven particle; give --support and --driven");
  }

  // Supports first (the driven particle is chosen among the others), then remove the driven
  // one from a detected or side support.
  std::set<int> supports;
  switch (support.kind) {
    case SupportSpec::Kind::none: break;
    case SupportSpec::Kind::ids:
      for (int id : support.ids) {
        check_id(id, n, "--support");
        supports.insert(id);
      }
      break;
    case SupportSpec::Kind::side:
      roles.support_side = support.side;
      for (int id : grid_side_particles(grid, support.side)) supports.insert(id);
      break;
    case SupportSpec::Kind::detect: {
      double least = HUGE_VAL;
      for (GridSide side : {GridSide::bottom, GridSide::top, GridSide::left, GridSide::right}) {
        const std::vector<int> ids = grid_side_particles(grid, side);
        double sum = 0;
        for (int id : ids) sum += motion_px[static_cast<std::size_t>(id)];
        const double mean = sum / static_cast<double>(ids.size());
        if (mean < least) {
          least = mean;
          roles.support_side = side;
        }
      }
      for (int id : grid_side_particles(grid, roles.support_side)) supports.insert(id);
      roles.support_detected = true;
      break;
    }
  }

  switch (driven.kind) {
    case DrivenSpec::Kind::id:
      check_id(driven.id, n, "--driven");
      roles.driven = driven.id;
      break;
    case DrivenSpec::Kind::point: {
      double best = HUGE_VAL;
      for (int i = 0; i < n; ++i) {
        const cv::Point2d d = grid.positions[static_cast<std::size_t>(i)] - driven.point;
        const double distance = std::hypot(d.x, d.y);
        if (distance < best) {
          best = distance;
          roles.driven = i;
        }
      }
      break;
    }
    case DrivenSpec::Kind::detect: {
      std::set<int> boundary;
      for (GridSide side : {GridSide::top, GridSide::bottom, GridSide::left, GridSide::right}) {
        for (int id : grid_side_particles(grid, side)) boundary.insert(id);
      }
      double most = -1;
      for (int id : boundary) {
        if (supports.count(id) != 0) continue;
        const double m = motion_px[static_cast<std::size_t>(id)];
        if (m > most) {
          most = m;
          roles.driven = id;
        }
      }
      if (roles.driven < 0) throw InputError("cannot detect the driven particle: every boundary particle is a support");
      roles.driven_detected = true;
      break;
    }
  }

  if (supports.count(roles.driven) != 0) {
    if (support.kind == SupportSpec::Kind::ids) {
      throw InputError("--driven: particle " + std::to_string(roles.driven) + " is also given as a support");
    }
    supports.erase(roles.driven);
  }
  if (static_cast<int>(supports.size()) + 1 >= n) {
    throw InputError("every particle would be a support or driven: nothing is left to observe deforming");
  }
  roles.support.assign(supports.begin(), supports.end());
  return roles;
}

}  // namespace pliant::vision::webcam
