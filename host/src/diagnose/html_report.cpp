// HTML report of a diagnosis: header, residual heat maps, trajectories of the located
// particles, candidate / parameter / signature tables. Self-contained, no JavaScript.
#include "pliant/host/diagnose/html_report.hpp"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <set>
#include <stdexcept>
#include <string>
#include <system_error>
#include <vector>

#include "svg_plot.hpp"

namespace pliant::host {
namespace {

namespace fs = std::filesystem;
using svg::escape;
using svg::number;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr std::size_t kMaxCells = 200'000;  // per residual map; more are binned
constexpr std::size_t kMaxRows = 400;       // particle rows per map; more are binned
constexpr int kLevels = 32;                 // colour levels of the maps and the bar
constexpr std::size_t kMaxTrajectoryPlots = 6;
constexpr std::size_t kMaxLinePoints = 2000;  // per series; longer ones keep min/max per bucket
constexpr std::size_t kMaxListedIds = 40;     // particle ids spelled out in the header

constexpr const char* kObservedColour = "#111111";
constexpr const char* kBaselineColour = "#e6550d";
constexpr const char* kAugmentedColour = "#3182bd";
constexpr const char* kWindowColour = "#fdae6b";
constexpr const char* kHeldOutColour = "#d62728";

// ------------------------------------------------------------------------------------------
// Shapes and the time axis

// Sizes the evidence claims, and which arrays actually match them.
struct Shape {
  std::size_t frames = 0;
  std::size_t particles = 0;
  std::size_t dimension = 0;
  bool times_monotonic = false;  // finite, non-decreasing times: plot against seconds
  bool held_out_ok = false;

  std::size_t cells() const { return frames * particles; }
  bool has_map(const std::vector<double>& map) const { return map.size() == cells(); }
  bool has_track(const std::vector<double>& track) const {
    return dimension > 0 && track.size() == cells() * dimension;
  }
};

Shape shape_of(const DiagnosisEvidence& evidence) {
  Shape shape;
  shape.frames = evidence.frame_times_s.size();
  shape.particles = evidence.particle_count > 0 ? static_cast<std::size_t>(evidence.particle_count) : 0;
  shape.dimension = evidence.dimension > 0 ? static_cast<std::size_t>(evidence.dimension) : 0;
  shape.times_monotonic = shape.frames > 0;
  for (std::size_t f = 0; f < shape.frames; ++f) {
    const double t = evidence.frame_times_s[f];
    if (!std::isfinite(t) || (f > 0 && t < evidence.frame_times_s[f - 1])) {
      shape.times_monotonic = false;
      break;
    }
  }
  shape.held_out_ok = evidence.held_out.size() == shape.frames;
  return shape;
}

// Fractional frame index of time `t` (clamped to the recorded span); needs monotonic times.
double frame_of_time(const std::vector<double>& times, double t) {
  if (times.empty() || !std::isfinite(t)) return kNaN;
  if (t <= times.front()) return 0.0;
  if (t >= times.back()) return static_cast<double>(times.size() - 1);
  const auto upper = std::upper_bound(times.begin(), times.end(), t);
  const auto f = static_cast<std::size_t>(upper - times.begin()) - 1;
  const double span = times[f + 1] - times[f];
  const double fraction = span > 0 ? (t - times[f]) / span : 0.0;
  return static_cast<double>(f) + fraction;
}

std::string unit_of(const DiagnosisEvidence& evidence) {
  return evidence.length_unit.empty() ? std::string("length unit") : evidence.length_unit;
}

// ------------------------------------------------------------------------------------------
// Residual maps

// A residual map reduced to at most kMaxCells cells: column c covers frames
// [frame_begin(c), frame_begin(c + 1)), row r covers particles [particle_begin(r), ...).
struct Grid {
  std::size_t frames = 0, particles = 0, rows = 0, cols = 0;
  std::size_t frame_begin(std::size_t c) const { return c * frames / cols; }
  std::size_t particle_begin(std::size_t r) const { return r * particles / rows; }
  bool binned() const { return rows != particles || cols != frames; }
};

Grid grid_for(const Shape& shape) {
  Grid grid;
  grid.frames = shape.frames;
  grid.particles = shape.particles;
  grid.rows = std::min(shape.particles, kMaxRows);
  grid.cols = shape.frames;
  if (grid.rows * grid.cols > kMaxCells) grid.cols = std::max<std::size_t>(1, kMaxCells / grid.rows);
  return grid;
}

// Mean of the finite values in each block; NaN where a block has none (unobserved).
std::vector<double> bin_map(const std::vector<double>& map, const Grid& grid) {
  std::vector<double> cells(grid.rows * grid.cols, kNaN);
  for (std::size_t r = 0; r < grid.rows; ++r) {
    const std::size_t p0 = grid.particle_begin(r);
    const std::size_t p1 = grid.particle_begin(r + 1);
    for (std::size_t c = 0; c < grid.cols; ++c) {
      const std::size_t f0 = grid.frame_begin(c);
      const std::size_t f1 = grid.frame_begin(c + 1);
      double sum = 0;
      std::size_t count = 0;
      for (std::size_t f = f0; f < f1; ++f) {
        for (std::size_t p = p0; p < p1; ++p) {
          const double v = map[f * grid.particles + p];
          if (std::isfinite(v)) {
            sum += std::fabs(v);
            ++count;
          }
        }
      }
      if (count > 0) cells[r * grid.cols + c] = sum / static_cast<double>(count);
    }
  }
  return cells;
}

// Shared colour scale of both maps: up to the 99.5th percentile so that a single glitch does
// not flatten everything else; `clamped` when larger values exist.
struct Scale {
  double top = 1;
  bool clamped = false;
};

Scale shared_scale(const std::vector<double>& a, const std::vector<double>& b, double fallback) {
  std::vector<double> values;
  values.reserve(a.size() + b.size());
  for (const auto* map : {&a, &b}) {
    for (const double v : *map) {
      if (std::isfinite(v)) values.push_back(v);
    }
  }
  Scale scale;
  if (values.empty()) {
    scale.top = fallback > 0 && std::isfinite(fallback) ? fallback : 1.0;
    return scale;
  }
  const double largest = *std::max_element(values.begin(), values.end());
  const auto k = static_cast<std::size_t>(0.995 * static_cast<double>(values.size() - 1));
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(k), values.end());
  double top = values[k];
  if (!(top > 0)) top = largest;
  if (!(top > 0)) top = fallback > 0 && std::isfinite(fallback) ? fallback : 1.0;
  scale.top = top;
  scale.clamped = largest > top * (1 + 1e-9);
  return scale;
}

int level_of(double value, double top) {
  const double t = value / top * kLevels;
  if (!(t > 0)) return 0;
  return static_cast<int>(std::min(t, static_cast<double>(kLevels - 1)));
}

struct MapPanel {
  std::string name;   // data-plot
  std::string title;  // <title> and heading line
  const std::vector<double>* cells = nullptr;
};

void draw_map(std::string& out, const MapPanel& panel, const Grid& grid, const Scale& scale, const Diagnosis& diagnosis,
              const DiagnosisEvidence& evidence, const Shape& shape) {
  const double map_w = 560;
  const double map_h = std::clamp(static_cast<double>(grid.rows) * 6.0, 160.0, 420.0);
  const double left = 74, top = 52;
  const double width = left + map_w + 150;
  const double height = top + map_h + 54;
  const std::string unit = unit_of(evidence);
  svg::open(out, panel.name, panel.title, width, height);
  svg::text(out, left, 16, panel.title, "font-size=\"13\" font-weight=\"bold\"");

  svg::Area area;
  area.left = left;
  area.top = top;
  area.width = map_w;
  area.height = map_h;
  area.x_min = 0;
  area.x_max = static_cast<double>(grid.cols);
  area.y_min = static_cast<double>(grid.rows);  // flipped: particle 0 at the top
  area.y_max = 0;
  const double cw = map_w / static_cast<double>(grid.cols);
  const double ch = map_h / static_cast<double>(grid.rows);

  // Unobserved cells show the hatched background through the gaps between drawn cells.
  const std::string hatch = "hatch-" + panel.name;
  out += "<defs><pattern id=\"" + escape(hatch) +
         "\" width=\"6\" height=\"6\" patternUnits=\"userSpaceOnUse\" "
         "patternTransform=\"rotate(45)\"><rect width=\"6\" height=\"6\" fill=\"" +
         std::string(svg::kMissingGrey) +
         "\"/><line x1=\"0\" y1=\"0\" x2=\"0\" y2=\"6\" stroke=\"#a6a6a6\" "
         "stroke-width=\"2\"/></pattern></defs>\n";
  out += "<rect x=\"" + svg::coord(left) + "\" y=\"" + svg::coord(top) + "\" width=\"" + svg::coord(map_w) +
         "\" height=\"" + svg::coord(map_h) + "\" fill=\"url(#" + escape(hatch) + ")\"/>\n";

  // Cells: one path per colour level, each horizontal run of equal level one stroked segment
  // in cell units (the transform scales a unit stroke to the cell height).
  std::vector<std::string> runs(static_cast<std::size_t>(kLevels));
  std::vector<std::size_t> last_row(static_cast<std::size_t>(kLevels), grid.rows);
  std::vector<std::size_t> last_end(static_cast<std::size_t>(kLevels), 0);
  const std::vector<double>& cells = *panel.cells;
  for (std::size_t r = 0; r < grid.rows; ++r) {
    std::size_t c = 0;
    while (c < grid.cols) {
      const double v = cells[r * grid.cols + c];
      if (!std::isfinite(v)) {
        ++c;
        continue;
      }
      const int level = level_of(v, scale.top);
      std::size_t end = c + 1;
      while (end < grid.cols) {
        const double w = cells[r * grid.cols + end];
        if (!std::isfinite(w) || level_of(w, scale.top) != level) break;
        ++end;
      }
      const auto l = static_cast<std::size_t>(level);
      std::string& d = runs[l];
      if (last_row[l] == r) {
        d += "m" + std::to_string(c - last_end[l]) + " 0";
      } else {
        d += "M" + std::to_string(c) + " " + std::to_string(r);
      }
      d += "h" + std::to_string(end - c);
      last_row[l] = r;
      last_end[l] = end;
      c = end;
    }
  }
  out += "<g fill=\"none\" stroke-width=\"1\" shape-rendering=\"crispEdges\" transform=\"translate(" +
         svg::coord(left) + " " + svg::coord(top + ch / 2) + ") scale(" + std::to_string(cw) + " " +
         std::to_string(ch) + ")\">\n";
  for (int level = 0; level < kLevels; ++level) {
    const std::string& d = runs[static_cast<std::size_t>(level)];
    if (d.empty()) continue;
    const double t = (static_cast<double>(level) + 0.5) / kLevels;
    out += "<path stroke=\"" + svg::colour(t) + "\" d=\"" + d + "\"/>\n";
  }
  out += "</g>\n";

  // Held-out frames: a red strip above the map.
  if (shape.held_out_ok) {
    std::string strip;
    std::size_t c = 0;
    while (c < grid.cols) {
      const auto held = [&](std::size_t col) {
        for (std::size_t f = grid.frame_begin(col); f < grid.frame_begin(col + 1); ++f) {
          if (evidence.held_out[f] != 0) return true;
        }
        return false;
      };
      if (!held(c)) {
        ++c;
        continue;
      }
      std::size_t end = c + 1;
      while (end < grid.cols && held(end)) ++end;
      strip += "M" + svg::coord(left + static_cast<double>(c) * cw) + " " + svg::coord(top - 10) + "h" +
               svg::coord(static_cast<double>(end - c) * cw) + "v7h" + svg::coord(-static_cast<double>(end - c) * cw) +
               "z";
      c = end;
    }
    if (!strip.empty()) {
      out += "<path fill=\"" + std::string(kHeldOutColour) + "\" d=\"" + strip + "\"/>\n";
      svg::text(out, left + map_w, top - 16, "red: frames held out of fitting",
                "text-anchor=\"end\" fill=\"" + std::string(kHeldOutColour) + "\"");
    }
  }

  // Location: a dashed box around the window and the span of located particles, and the
  // located particles as ticks on the right.
  const Location& location = diagnosis.location;
  const double scale_x = static_cast<double>(grid.cols) / static_cast<double>(grid.frames);
  const double scale_y = static_cast<double>(grid.rows) / static_cast<double>(grid.particles);
  std::size_t first_id = grid.particles, last_id = 0;
  for (const int id : location.particles) {
    if (id < 0 || static_cast<std::size_t>(id) >= grid.particles) continue;
    first_id = std::min(first_id, static_cast<std::size_t>(id));
    last_id = std::max(last_id, static_cast<std::size_t>(id));
  }
  if (shape.times_monotonic && first_id <= last_id && location.t_end >= location.t_start) {
    const double f0 = frame_of_time(evidence.frame_times_s, location.t_start);
    const double f1 = frame_of_time(evidence.frame_times_s, location.t_end);
    if (std::isfinite(f0) && std::isfinite(f1)) {
      const double x0 = area.px(std::floor(f0) * scale_x);
      const double x1 = area.px((std::floor(f1) + 1) * scale_x);
      const double y0 = area.py(std::floor(static_cast<double>(first_id) * scale_y));
      const double y1 = area.py(std::floor(static_cast<double>(last_id) * scale_y) + 1);
      out += "<rect x=\"" + svg::coord(x0) + "\" y=\"" + svg::coord(y0) + "\" width=\"" +
             svg::coord(std::max(x1 - x0, 1.0)) + "\" height=\"" + svg::coord(std::max(y1 - y0, 1.0)) +
             "\" fill=\"none\" stroke=\"#ffffff\" stroke-width=\"1.5\" "
             "stroke-dasharray=\"5 3\"/>\n";
    }
  }
  std::string marks;
  std::size_t marked = 0;
  for (const int id : location.particles) {
    if (id < 0 || static_cast<std::size_t>(id) >= grid.particles || marked >= 1000) continue;
    const double y = area.py((static_cast<double>(id) + 0.5) * scale_y);
    marks += "M" + svg::coord(left + map_w + 1) + " " + svg::coord(y) + "l6 -3v6z";
    ++marked;
  }
  if (!marks.empty()) out += "<path fill=\"" + std::string(kHeldOutColour) + "\" d=\"" + marks + "\"/>\n";

  // Axes: time (or frame number) along x, particle id along y.
  svg::Ticks x_ticks;
  std::string x_label;
  if (shape.times_monotonic) {
    const svg::Ticks t = svg::linear_ticks(evidence.frame_times_s.front(), evidence.frame_times_s.back(), 6);
    for (std::size_t i = 0; i < t.at.size(); ++i) {
      x_ticks.at.push_back((frame_of_time(evidence.frame_times_s, t.at[i]) + 0.5) * scale_x);
      x_ticks.labels.push_back(t.labels[i]);
    }
    x_label = "time (s)";
  } else {
    const svg::Ticks t = svg::linear_ticks(0, static_cast<double>(grid.frames - 1), 6);
    for (std::size_t i = 0; i < t.at.size(); ++i) {
      x_ticks.at.push_back((t.at[i] + 0.5) * scale_x);
      x_ticks.labels.push_back(t.labels[i]);
    }
    x_label = "frame (times not monotonic)";
  }
  svg::Ticks y_ticks;
  const svg::Ticks ids = svg::linear_ticks(0, static_cast<double>(grid.particles - 1), 6);
  for (std::size_t i = 0; i < ids.at.size(); ++i) {
    if (ids.at[i] != std::floor(ids.at[i])) continue;
    y_ticks.at.push_back((ids.at[i] + 0.5) * static_cast<double>(grid.rows) / static_cast<double>(grid.particles));
    y_ticks.labels.push_back(ids.labels[i]);
  }
  svg::axes(out, area, x_ticks, y_ticks, x_label, "particle id");
  svg::colour_bar(out, left + map_w + 26, top, 14, map_h, 0.0, scale.top, kLevels, "mean |residual| (" + unit + ")",
                  scale.clamped);
  // Legend for missing data.
  out += "<rect x=\"" + svg::coord(left) + "\" y=\"" + svg::coord(top - 24) +
         "\" width=\"12\" height=\"10\" fill=\"url(#" + escape(hatch) + ")\" stroke=\"#a6a6a6\"/>\n";
  svg::text(out, left + 16, top - 15, "unobserved");
  svg::text(out, left + 96, top - 15, "dashed box: location window; red ticks: located particles");
  svg::close(out);
}

// ------------------------------------------------------------------------------------------
// Trajectories

// One particle's displacement series along one axis.
struct Series {
  std::vector<double> values;  // [frames], NaN where missing
  bool present = false;
};

Series component(const std::vector<double>& track, const Shape& shape, std::size_t id, std::size_t axis,
                 double origin) {
  Series series;
  if (!shape.has_track(track)) return series;
  series.present = true;
  series.values.resize(shape.frames, kNaN);
  for (std::size_t f = 0; f < shape.frames; ++f) {
    const double v = track[(f * shape.particles + id) * shape.dimension + axis];
    if (std::isfinite(v)) series.values[f] = v - origin;
  }
  return series;
}

// Long series keep, per bucket, the smallest and largest value in time order, so spikes stay.
void decimate(const std::vector<double>& xs, const std::vector<double>& ys, std::vector<double>& out_x,
              std::vector<double>& out_y) {
  const std::size_t n = std::min(xs.size(), ys.size());
  if (n <= kMaxLinePoints) {
    out_x.assign(xs.begin(), xs.begin() + static_cast<std::ptrdiff_t>(n));
    out_y.assign(ys.begin(), ys.begin() + static_cast<std::ptrdiff_t>(n));
    return;
  }
  const std::size_t buckets = kMaxLinePoints / 2;
  out_x.clear();
  out_y.clear();
  for (std::size_t b = 0; b < buckets; ++b) {
    const std::size_t i0 = b * n / buckets;
    const std::size_t i1 = (b + 1) * n / buckets;
    std::size_t lo = i1, hi = i1;
    for (std::size_t i = i0; i < i1; ++i) {
      if (!std::isfinite(ys[i])) continue;
      if (lo == i1 || ys[i] < ys[lo]) lo = i;
      if (hi == i1 || ys[i] > ys[hi]) hi = i;
    }
    if (lo == i1) {  // nothing observed in this bucket: break the line
      out_x.push_back(xs[i0]);
      out_y.push_back(kNaN);
      continue;
    }
    for (const std::size_t i : {std::min(lo, hi), std::max(lo, hi)}) {
      out_x.push_back(xs[i]);
      out_y.push_back(ys[i]);
      if (lo == hi) break;
    }
  }
}

void draw_trajectory(std::string& out, std::size_t id, const Diagnosis& diagnosis, const DiagnosisEvidence& evidence,
                     const Shape& shape) {
  const std::string unit = unit_of(evidence);
  const auto at = [&](const std::vector<double>& track, std::size_t f, std::size_t axis) {
    return track[(f * shape.particles + id) * shape.dimension + axis];
  };
  // The axis of largest motion of the observed positions (simulated ones if never observed).
  const std::vector<double>* reference = &evidence.observed;
  const auto observed_anywhere = [&](const std::vector<double>& track) {
    for (std::size_t f = 0; f < shape.frames; ++f) {
      if (std::isfinite(at(track, f, 0))) return true;
    }
    return false;
  };
  if (!observed_anywhere(evidence.observed) && shape.has_track(evidence.simulated_baseline)) {
    reference = &evidence.simulated_baseline;
  }
  std::size_t axis = 0;
  double widest = -1;
  for (std::size_t k = 0; k < shape.dimension; ++k) {
    double lo = std::numeric_limits<double>::infinity();
    double hi = -lo;
    for (std::size_t f = 0; f < shape.frames; ++f) {
      const double v = at(*reference, f, k);
      if (!std::isfinite(v)) continue;
      lo = std::min(lo, v);
      hi = std::max(hi, v);
    }
    if (hi >= lo && hi - lo > widest) {
      widest = hi - lo;
      axis = k;
    }
  }
  double origin = kNaN;
  for (std::size_t f = 0; f < shape.frames && std::isnan(origin); ++f) {
    const double v = at(*reference, f, axis);
    if (std::isfinite(v)) origin = v;
  }
  const char axis_name = static_cast<char>('x' + static_cast<int>(std::min<std::size_t>(axis, 2)));

  const Series observed = component(evidence.observed, shape, id, axis, origin);
  const Series baseline = component(evidence.simulated_baseline, shape, id, axis, origin);
  const Series augmented = component(evidence.simulated_augmented, shape, id, axis, origin);

  std::vector<double> xs(shape.frames);
  for (std::size_t f = 0; f < shape.frames; ++f) {
    xs[f] = shape.times_monotonic ? evidence.frame_times_s[f] : static_cast<double>(f);
  }
  double lo = std::numeric_limits<double>::infinity();
  double hi = -lo;
  for (const Series* s : {&observed, &baseline, &augmented}) {
    for (const double v : s->values) {
      if (!std::isfinite(v)) continue;
      lo = std::min(lo, v);
      hi = std::max(hi, v);
    }
  }
  const bool any = hi >= lo;
  if (!any) {
    lo = -1;
    hi = 1;
  }
  const double pad = hi > lo ? 0.08 * (hi - lo) : std::max(std::fabs(hi) * 0.1, 1e-9);
  lo -= pad;
  hi += pad;

  const std::string title = "Particle " + std::to_string(id) + ": displacement along " + std::string(1, axis_name) +
                            " from its first position";
  const double width = 380, height = 250;
  svg::open(out, "trajectory_" + std::to_string(id), title, width, height);
  svg::text(out, 70, 16, "particle " + std::to_string(id), "font-size=\"13\" font-weight=\"bold\"");
  svg::Area area;
  area.left = 70;
  area.top = 28;
  area.width = width - 84;
  area.height = height - 28 - 52;
  area.x_min = xs.empty() ? 0 : xs.front();
  area.x_max = xs.empty() ? 1 : xs.back();
  area.y_min = lo;
  area.y_max = hi;

  const Location& location = diagnosis.location;
  if (shape.times_monotonic && std::isfinite(location.t_start) && std::isfinite(location.t_end) &&
      location.t_end >= location.t_start && location.t_end >= area.x_min && location.t_start <= area.x_max) {
    const double x0 = area.px(std::max(location.t_start, area.x_min));
    const double x1 = area.px(std::min(location.t_end, area.x_max));
    out += "<rect x=\"" + svg::coord(x0) + "\" y=\"" + svg::coord(area.top) + "\" width=\"" +
           svg::coord(std::max(x1 - x0, 1.0)) + "\" height=\"" + svg::coord(area.height) + "\" fill=\"" +
           kWindowColour + "\" fill-opacity=\"0.35\"/>\n";
  }
  const auto line = [&](const Series& s, const std::string& attributes) {
    if (!s.present) return;
    std::vector<double> dx, dy;
    decimate(xs, s.values, dx, dy);
    svg::polyline(out, area, dx, dy, attributes);
  };
  line(observed, "stroke=\"" + std::string(kObservedColour) + "\" stroke-width=\"2.2\"");
  line(baseline, "stroke=\"" + std::string(kBaselineColour) + "\" stroke-width=\"1.5\" stroke-dasharray=\"6 3\"");
  line(augmented, "stroke=\"" + std::string(kAugmentedColour) + "\" stroke-width=\"1.5\"");
  if (!any) {
    svg::text(out, area.left + area.width / 2, area.top + area.height / 2, "never observed or simulated",
              "text-anchor=\"middle\" fill=\"#888888\"");
  }
  svg::axes(out, area, svg::linear_ticks(area.x_min, area.x_max, 5), svg::linear_ticks(lo, hi, 5),
            shape.times_monotonic ? "time (s)" : "frame (times not monotonic)",
            std::string("displacement ") + axis_name + " (" + unit + ")");
  svg::close(out);
}

// ------------------------------------------------------------------------------------------
// Page

std::string with_std(const std::map<std::string, double>& values, const std::map<std::string, double>& stds,
                     const std::string& name) {
  const auto v = values.find(name);
  if (v == values.end()) return "&mdash;";
  std::string text = escape(number(v->second, 4));
  const auto s = stds.find(name);
  if (s != stds.end()) text += " &plusmn; " + escape(number(s->second, 2));
  return text;
}

std::string parameter_list(const std::map<std::string, double>& values, const std::map<std::string, double>& stds) {
  if (values.empty()) return "&mdash;";
  std::string text;
  for (const auto& entry : values) {
    if (!text.empty()) text += "<br>";
    text += "<code>" + escape(entry.first) + "</code> = " + with_std(values, stds, entry.first);
  }
  return text;
}

std::string id_list(const std::vector<int>& ids) {
  if (ids.empty()) return "none";
  std::string text;
  for (std::size_t i = 0; i < ids.size() && i < kMaxListedIds; ++i) {
    if (i > 0) text += ", ";
    text += std::to_string(ids[i]);
  }
  if (ids.size() > kMaxListedIds) {
    text += ", &hellip; (" + std::to_string(ids.size()) + " in all)";
  }
  return text;
}

constexpr const char* kStyle = R"(
body { font-family: sans-serif; margin: 1.5em auto; max-width: 1200px; color: #222; padding: 0 1em; }
h1 { font-size: 1.5em; margin-bottom: 0.2em; }
h2 { font-size: 1.15em; margin-top: 1.6em; border-bottom: 1px solid #ccc; }
.verdict { display: inline-block; padding: 0.1em 0.6em; border-radius: 0.3em; font-weight: bold; }
.verdict-consistent { background: #d9f0d3; }
.verdict-missing_physics { background: #fde0c5; }
.explanation { font-size: 1.05em; max-width: 60em; }
table { border-collapse: collapse; margin: 0.5em 0; }
th, td { border: 1px solid #ccc; padding: 0.25em 0.6em; text-align: left; vertical-align: top; }
th { background: #f2f2f2; }
td.num { text-align: right; font-variant-numeric: tabular-nums; }
tr.chosen td { background: #eef5fb; font-weight: bold; }
.plots { display: flex; flex-wrap: wrap; gap: 0.8em; }
svg.plot { display: block; max-width: 100%; height: auto; border: 1px solid #e3e3e3; }
.note { color: #555; font-style: italic; }
.legend span { margin-right: 1.2em; }
)";

void header(std::string& out, const Diagnosis& d, const DiagnosisEvidence& evidence) {
  const std::string unit = escape(unit_of(evidence));
  out += "<h1>Diagnosis of <code>" + escape(d.recording) + "</code></h1>\n";
  out += "<p><span class=\"verdict verdict-" + escape(d.verdict) + "\" data-field=\"verdict\">" + escape(d.verdict) +
         "</span> &nbsp; effect: <strong data-field=\"effect\">" + escape(d.effect) + "</strong></p>\n";
  if (!d.explanation.empty()) {
    out += "<p class=\"explanation\" data-field=\"explanation\">" + escape(d.explanation) + "</p>\n";
  }
  out += "<table data-table=\"summary\">\n";
  const auto row = [&](const std::string& name, const std::string& value) {
    out += "<tr><th>" + name + "</th><td>" + value + "</td></tr>\n";
  };
  // FEM on a force-only recording: no free node position is compared, the force rows say it all.
  const bool force_only = !std::isfinite(d.baseline.rms) && std::isfinite(d.baseline.force_rms);
  if (force_only) {
    row("model", "<code>" + escape(d.baseline.model) +
                     "</code> &nbsp; (no free node position is compared: "
                     "the evidence is the force)");
  } else {
    row("measurement noise rms", escape(number(d.noise_rms, 3)) + " " + unit);
    row("baseline rms (held-out)", escape(number(d.baseline.rms, 3)) + " " + unit + " &nbsp; (model <code>" +
                                       escape(d.baseline.model) + "</code>)");
    row("augmented rms (held-out)", escape(number(d.augmented.rms, 3)) + " " + unit);
  }
  row("improvement",
      std::isfinite(d.improvement) ? escape(number(100.0 * d.improvement, 3)) + " %" : std::string("n/a"));
  if (d.noise_rms > 0 && std::isfinite(d.baseline.rms)) {
    row("baseline rms / noise", escape(number(d.baseline.rms / d.noise_rms, 3)));
  }
  if (std::isfinite(d.force_noise_rms) || std::isfinite(d.baseline.force_rms)) {
    row("force noise rms", escape(number(d.force_noise_rms, 3)) + " N");
    row("baseline force rms (held-out)", escape(number(d.baseline.force_rms, 3)) + " N");
    row("augmented force rms (held-out)", escape(number(d.augmented.force_rms, 3)) + " N");
  }
  row("located particles", id_list(d.location.particles));
  if (!d.location.particles.empty()) {
    row("location window",
        escape(number(d.location.t_start, 4)) + " s &ndash; " + escape(number(d.location.t_end, 4)) + " s");
  }
  row("recording", escape(std::to_string(evidence.frame_times_s.size())) + " frames, " +
                       escape(std::to_string(evidence.particle_count)) + " particles, " +
                       escape(std::to_string(evidence.dimension)) + "D; fixed: " + id_list(evidence.fixed) +
                       "; driven: " + id_list(evidence.driven));
  out += "</table>\n";
}

void maps_section(std::string& out, const Diagnosis& d, const DiagnosisEvidence& evidence, const Shape& shape) {
  out += "<h2>Residual maps</h2>\n";
  const bool consistent = d.verdict == "consistent";
  const bool have_before = shape.has_map(evidence.residual_baseline);
  bool have_after = shape.has_map(evidence.residual_augmented);
  const std::vector<double>* after_source = &evidence.residual_augmented;
  if (!have_after && consistent && have_before) {  // consistent: augmented is the baseline
    after_source = &evidence.residual_baseline;
    have_after = true;
  }
  if (!have_before && !have_after) {
    out +=
        "<p class=\"note\">No residual map: the residual arrays do not hold frames &times; "
        "particles values.</p>\n";
    return;
  }
  const Grid grid = grid_for(shape);
  const std::vector<double> before = have_before ? bin_map(evidence.residual_baseline, grid) : std::vector<double>();
  const std::vector<double> after = have_after ? bin_map(*after_source, grid) : std::vector<double>();
  const Scale scale = shared_scale(before, after, d.noise_rms);
  out +=
      "<p>|observed &minus; simulated| per particle and frame, on one colour scale for both "
      "maps (" +
      escape(unit_of(evidence)) + ").";
  if (grid.binned()) {
    out += " The recording has " + std::to_string(shape.frames) + " frames &times; " + std::to_string(shape.particles) +
           " particles; each cell shows the mean over a block "
           "of about " +
           std::to_string((shape.frames + grid.cols - 1) / grid.cols) + " frames &times; " +
           std::to_string((shape.particles + grid.rows - 1) / grid.rows) + " particles.";
  }
  out += "</p>\n<div class=\"plots\">\n";
  if (have_before) {
    draw_map(
        out,
        {"residual_before",
         "(a) before: baseline " + d.baseline.model + ", rms " + number(d.baseline.rms, 3) + " " + unit_of(evidence),
         &before},
        grid, scale, d, evidence, shape);
  } else {
    out += "<p class=\"note\">No baseline residual map (array size mismatch).</p>\n";
  }
  if (have_after) {
    draw_map(
        out,
        {"residual_after",
         "(b) after: baseline + " + d.effect + ", rms " + number(d.augmented.rms, 3) + " " + unit_of(evidence), &after},
        grid, scale, d, evidence, shape);
  } else {
    out += "<p class=\"note\">No augmented residual map (array size mismatch).</p>\n";
  }
  out += "</div>\n";
}

void trajectories_section(std::string& out, const Diagnosis& d, const DiagnosisEvidence& evidence, const Shape& shape) {
  out += "<h2>(c) Trajectories of the located particles</h2>\n";
  if (!shape.has_track(evidence.observed)) {
    out +=
        "<p class=\"note\">No trajectories: the observed positions do not hold frames "
        "&times; particles &times; dimension values.</p>\n";
    return;
  }
  std::vector<std::size_t> ids;
  std::set<std::size_t> seen;
  for (const int id : d.location.particles) {
    if (id < 0 || static_cast<std::size_t>(id) >= shape.particles) continue;
    const auto u = static_cast<std::size_t>(id);
    if (!seen.insert(u).second) continue;
    if (ids.size() < kMaxTrajectoryPlots) ids.push_back(u);
  }
  if (ids.empty()) {
    out +=
        "<p class=\"note\">No particles were located, so there are no trajectories to "
        "compare.</p>\n";
    return;
  }
  out +=
      "<p class=\"legend\">Displacement from the first observed position along the axis in "
      "which the particle moves most. <span style=\"color:" +
      std::string(kObservedColour) + "\">&#9473; observed</span><span style=\"color:" + kBaselineColour +
      "\">&#9476; baseline</span><span style=\"color:" + kAugmentedColour +
      "\">&#9473; augmented</span><span style=\"background:" + kWindowColour +
      "\">&nbsp;location window&nbsp;</span></p>\n";
  if (seen.size() > ids.size()) {
    out += "<p class=\"note\">Showing the first " + std::to_string(ids.size()) + " of " + std::to_string(seen.size()) +
           " located particles.</p>\n";
  }
  if (!shape.has_track(evidence.simulated_baseline) || !shape.has_track(evidence.simulated_augmented)) {
    out += "<p class=\"note\">Some simulated trajectories are missing and are not drawn.</p>\n";
  }
  out += "<div class=\"plots\">\n";
  for (const std::size_t id : ids) draw_trajectory(out, id, d, evidence, shape);
  out += "</div>\n";
}

// FEM with a measured wrench: the force along its main direction (that of the largest measured
// force) against time, measured / baseline / augmented. Nothing when there is no force.
void force_section(std::string& out, const Diagnosis& d, const DiagnosisEvidence& evidence) {
  const std::size_t frames = evidence.frame_times_s.size();
  if (evidence.force_observed.empty()) return;
  out += "<h2>Force on the tool</h2>\n";
  if (evidence.force_observed.size() != 3 * frames || evidence.force_baseline.size() != 3 * frames ||
      evidence.force_augmented.size() != 3 * frames) {
    out += "<p class=\"note\">No force plot: the force arrays do not hold frames &times; 3 values.</p>\n";
    return;
  }
  double direction[3] = {0, 0, 1};
  double peak = 0;
  for (std::size_t f = 0; f < frames; ++f) {
    const double* v = &evidence.force_observed[3 * f];
    const double norm = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (std::isfinite(norm) && norm > peak) {
      peak = norm;
      for (int a = 0; a < 3; ++a) direction[a] = v[a] / norm;
    }
  }
  const auto along = [&](const std::vector<double>& force) {
    std::vector<double> values(frames, kNaN);
    for (std::size_t f = 0; f < frames; ++f) {
      values[f] = force[3 * f] * direction[0] + force[3 * f + 1] * direction[1] + force[3 * f + 2] * direction[2];
    }
    return values;
  };
  const std::vector<double> observed = along(evidence.force_observed);
  const std::vector<double> baseline = along(evidence.force_baseline);
  const std::vector<double> augmented = along(evidence.force_augmented);
  std::vector<double> xs(frames);
  for (std::size_t f = 0; f < frames; ++f) xs[f] = evidence.frame_times_s[f];
  double lo = std::numeric_limits<double>::infinity();
  double hi = -lo;
  for (const std::vector<double>* series : {&observed, &baseline, &augmented}) {
    for (const double v : *series) {
      if (!std::isfinite(v)) continue;
      lo = std::min(lo, v);
      hi = std::max(hi, v);
    }
  }
  if (!(hi >= lo) || frames < 2) {
    out += "<p class=\"note\">No force plot: no finite force values.</p>\n";
    return;
  }
  const double pad = hi > lo ? 0.05 * (hi - lo) : std::max(std::fabs(hi) * 0.1, 1e-9);
  lo -= pad;
  hi += pad;
  out +=
      "<p class=\"legend\">Force of the tool on the object along the direction of the largest measured force "
      "(" +
      escape(number(direction[0], 3)) + ", " + escape(number(direction[1], 3)) + ", " +
      escape(number(direction[2], 3)) + "). <span style=\"color:" + std::string(kObservedColour) +
      "\">&#9473; measured</span><span style=\"color:" + kBaselineColour +
      "\">&#9476; baseline</span><span style=\"color:" + kAugmentedColour + "\">&#9473; augmented</span></p>\n";
  const double width = 760, height = 320;
  svg::open(out, "force", "Measured and simulated force against time", width, height);
  svg::Area area;
  area.left = 80;
  area.top = 20;
  area.width = width - 100;
  area.height = height - 20 - 52;
  area.x_min = xs.front();
  area.x_max = xs.back() > xs.front() ? xs.back() : xs.front() + 1.0;
  area.y_min = lo;
  area.y_max = hi;
  const auto line = [&](const std::vector<double>& values, const std::string& attributes) {
    std::vector<double> dx, dy;
    decimate(xs, values, dx, dy);
    svg::polyline(out, area, dx, dy, attributes);
  };
  line(observed, "stroke=\"" + std::string(kObservedColour) + "\" stroke-width=\"2.2\"");
  line(baseline, "stroke=\"" + std::string(kBaselineColour) + "\" stroke-width=\"1.5\" stroke-dasharray=\"6 3\"");
  line(augmented, "stroke=\"" + std::string(kAugmentedColour) + "\" stroke-width=\"1.5\"");
  svg::axes(out, area, svg::linear_ticks(area.x_min, area.x_max, 6), svg::linear_ticks(lo, hi, 5), "time (s)",
            "force (N)");
  svg::close(out);
  if (d.verdict == "consistent") out += "<p class=\"note\">Consistent: the augmented curve is the baseline.</p>\n";
}

void tables_section(std::string& out, const Diagnosis& d, const DiagnosisEvidence& evidence) {
  const std::string unit = escape(unit_of(evidence));
  out += "<h2>(d) Candidate effects</h2>\n";
  if (d.candidates.empty()) {
    out += "<p class=\"note\">No candidate effects were tried.</p>\n";
  } else {
    // FEM with a measured wrench: a held-out force rms column too.
    bool forces = false;
    for (const Candidate& c : d.candidates) forces = forces || std::isfinite(c.force_rms);
    out += "<table data-table=\"candidates\">\n<tr><th>#</th><th>effect</th><th>held-out rms (" + unit + ")</th>" +
           (forces ? "<th>held-out force rms (N)</th>" : "") +
           "<th>BIC</th><th>parameters (&plusmn; 1 std)</th></tr>\n";
    for (std::size_t i = 0; i < d.candidates.size(); ++i) {
      const Candidate& c = d.candidates[i];
      const bool chosen = d.verdict != "consistent" && c.effect == d.effect;
      out += std::string(chosen ? "<tr class=\"chosen\">" : "<tr>") + "<td class=\"num\">" + std::to_string(i + 1) +
             "</td><td>" + escape(c.effect) + (chosen ? " (chosen)" : "") + "</td><td class=\"num\">" +
             escape(number(c.rms, 3)) + "</td>" +
             (forces ? "<td class=\"num\">" + escape(number(c.force_rms, 3)) + "</td>" : std::string()) +
             "<td class=\"num\">" + escape(number(c.bic, 6)) + "</td><td>" +
             parameter_list(c.parameters, c.parameter_std) + "</td></tr>\n";
    }
    out += "</table>\n";
  }

  out += "<h3>Baseline and augmented parameters</h3>\n";
  std::set<std::string> names;
  for (const auto& p : d.baseline.parameters) names.insert(p.first);
  for (const auto& p : d.augmented.parameters) names.insert(p.first);
  if (names.empty()) {
    out += "<p class=\"note\">No fitted parameters.</p>\n";
  } else {
    out +=
        "<table data-table=\"parameters\">\n<tr><th>parameter</th><th>baseline</th>"
        "<th>augmented</th><th>shift</th></tr>\n";
    for (const std::string& name : names) {
      const auto b = d.baseline.parameters.find(name);
      const auto a = d.augmented.parameters.find(name);
      std::string shift;
      if (b == d.baseline.parameters.end()) {
        shift = "added by the effect";
      } else if (a == d.augmented.parameters.end()) {
        shift = "dropped";
      } else {
        const double delta = a->second - b->second;
        shift = escape((delta >= 0 ? "+" : "") + number(delta, 3));
        if (delta == 0) {
          shift = "unchanged";
        } else if (b->second != 0 && std::isfinite(delta)) {
          shift += " (" + escape((delta >= 0 ? "+" : "") + number(100.0 * delta / std::fabs(b->second), 3)) + " %)";
        }
      }
      out += "<tr><td><code>" + escape(name) + "</code></td><td class=\"num\">" +
             with_std(d.baseline.parameters, d.baseline.parameter_std, name) + "</td><td class=\"num\">" +
             with_std(d.augmented.parameters, d.augmented.parameter_std, name) + "</td><td class=\"num\">" + shift +
             "</td></tr>\n";
    }
    out += "</table>\n";
  }

  out += "<h2>(e) Signatures</h2>\n";
  if (evidence.signatures.empty()) {
    out += "<p class=\"note\">No signature statistics were recorded.</p>\n";
  } else {
    out += "<table data-table=\"signatures\">\n<tr><th>signature</th><th>value</th></tr>\n";
    for (const auto& s : evidence.signatures) {
      out += "<tr><td><code>" + escape(s.first) + "</code></td><td class=\"num\">" + escape(number(s.second, 4)) +
             "</td></tr>\n";
    }
    out += "</table>\n";
  }
}

std::string one_line(const std::string& text) {
  std::string out;
  for (const char c : text) {
    const auto byte = static_cast<unsigned char>(c);
    out.push_back(byte < 0x20 || byte == 0x7f ? '?' : c);
  }
  return out;
}

}  // namespace

std::string diagnosis_html(const Diagnosis& diagnosis, const DiagnosisEvidence& evidence) {
  const Shape shape = shape_of(evidence);
  std::string out;
  out.reserve(64 * 1024);
  out +=
      "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
      "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n"
      "<meta name=\"generator\" content=\"pliant diagnose\">\n<title>pliant diagnosis: " +
      escape(diagnosis.recording) + "</title>\n<style>" + kStyle + "</style>\n</head>\n<body>\n";
  header(out, diagnosis, evidence);
  if (shape.frames == 0 || shape.particles == 0) {
    out += "<p class=\"note\" data-note=\"no-data\">No data to plot: the evidence holds " +
           std::to_string(shape.frames) + " frames and " + std::to_string(shape.particles) + " particles.</p>\n";
  } else {
    force_section(out, diagnosis, evidence);
    // Force only (FEM, no free node position compared): the maps and trajectories would show
    // constrained nodes that follow their own observations, so they are left out.
    if (!std::isfinite(diagnosis.baseline.rms) && !evidence.force_observed.empty()) {
      out +=
          "<p class=\"note\" data-note=\"force-only\">No residual maps or trajectories: no free node "
          "position is compared with the simulation; the force above is the evidence.</p>\n";
    } else {
      maps_section(out, diagnosis, evidence, shape);
      trajectories_section(out, diagnosis, evidence, shape);
    }
  }
  tables_section(out, diagnosis, evidence);
  out +=
      "<p class=\"note\">Generated by pliant diagnose (pliant-diagnosis v1). "
      "Self-contained page: no scripts, no external resources.</p>\n</body>\n</html>\n";
  return out;
}

void write_diagnosis_report(const Diagnosis& diagnosis, const DiagnosisEvidence& evidence,
                            const std::string& directory) {
  const fs::path dir(directory);
  std::error_code error;
  fs::create_directories(dir, error);
  if (error || !fs::is_directory(dir)) {
    throw std::runtime_error("cannot create report directory " + one_line(directory) + ": " +
                             (error ? error.message() : std::string("not a directory")));
  }
  const std::string html = diagnosis_html(diagnosis, evidence);
  const fs::path final_path = dir / "index.html";
  // Unique per process and call, so concurrent writers never share a temporary file.
  static std::atomic<unsigned> serial{0};
  const fs::path temporary =
      dir / (".index.html." + std::to_string(::getpid()) + "." + std::to_string(serial.fetch_add(1)) + ".tmp");
  {
    errno = 0;
    std::ofstream file(temporary, std::ios::binary | std::ios::trunc);
    if (file) file.write(html.data(), static_cast<std::streamsize>(html.size()));
    file.close();
    if (!file) {
      const std::string cause = errno != 0 ? std::strerror(errno) : "write failed";
      std::error_code ignored;
      fs::remove(temporary, ignored);
      throw std::runtime_error("cannot write " + one_line(temporary.string()) + ": " + cause);
    }
  }
  fs::rename(temporary, final_path, error);
  if (error) {
    const std::string cause = error.message();
    std::error_code ignored;
    fs::remove(temporary, ignored);
    throw std::runtime_error("cannot move the report into place at " + one_line(final_path.string()) + ": " + cause);
  }
}

}  // namespace pliant::host
