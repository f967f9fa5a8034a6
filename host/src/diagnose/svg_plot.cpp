// Inline-SVG drawing kit for the diagnosis report (see svg_plot.hpp).
#include "svg_plot.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <string>

namespace pliant::host::svg {
namespace {

constexpr const char* kAxisColour = "#333333";
constexpr const char* kFont = "font-family=\"sans-serif\" font-size=\"11\" fill=\"#222222\"";

// Control points of the ramp, evenly spaced on [0, 1] (sampled from matplotlib's viridis).
constexpr std::array<std::array<int, 3>, 9> kRamp = {{
    {68, 1, 84},
    {71, 45, 123},
    {59, 82, 139},
    {44, 114, 142},
    {33, 145, 140},
    {40, 174, 128},
    {94, 201, 98},
    {173, 220, 48},
    {253, 231, 37},
}};

std::string hex(int r, int g, int b) {
  char buffer[8];
  std::snprintf(buffer, sizeof buffer, "#%02x%02x%02x", r, g, b);
  return buffer;
}

}  // namespace

std::string escape(std::string_view text) {
  std::string out;
  out.reserve(text.size() + text.size() / 8);
  for (const char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&#39;"; break;
      default: {
        const auto byte = static_cast<unsigned char>(c);
        const bool control = (byte < 0x20 && c != '\t' && c != '\n') || byte == 0x7f;
        out.push_back(control ? '?' : c);
      }
    }
  }
  return out;
}

std::string number(double value, int digits) {
  if (std::isnan(value)) return "n/a";
  if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
  char buffer[40];
  std::snprintf(buffer, sizeof buffer, "%.*g", std::clamp(digits, 1, 17), value);
  return buffer;
}

std::string coord(double value) {
  if (!std::isfinite(value)) return "0";
  char buffer[40];
  std::snprintf(buffer, sizeof buffer, "%.2f", value);
  std::string text = buffer;
  while (!text.empty() && text.back() == '0') text.pop_back();
  if (!text.empty() && text.back() == '.') text.pop_back();
  if (text == "-0") text = "0";
  return text;
}

std::string colour(double t) {
  if (std::isnan(t)) return kMissingGrey;
  t = std::clamp(t, 0.0, 1.0);
  const double scaled = t * static_cast<double>(kRamp.size() - 1);
  const auto i = std::min(static_cast<std::size_t>(scaled), kRamp.size() - 2);
  const double f = scaled - static_cast<double>(i);
  std::array<int, 3> rgb{};
  for (std::size_t k = 0; k < 3; ++k) {
    const double a = kRamp[i][k];
    const double b = kRamp[i + 1][k];
    rgb[k] = static_cast<int>(std::lround(a + (b - a) * f));
  }
  return hex(rgb[0], rgb[1], rgb[2]);
}

Ticks linear_ticks(double lo, double hi, int target) {
  Ticks ticks;
  if (!std::isfinite(lo) || !std::isfinite(hi) || !std::isfinite(hi - lo)) return ticks;
  if (hi < lo) std::swap(lo, hi);
  if (hi == lo) {
    ticks.at.push_back(lo);
    ticks.labels.push_back(number(lo, 4));
    return ticks;
  }
  const double raw = (hi - lo) / static_cast<double>(std::max(target, 1));
  const double magnitude = std::pow(10.0, std::floor(std::log10(raw)));
  double step = 10.0 * magnitude;
  for (const double m : {1.0, 2.0, 5.0}) {
    if (raw <= m * magnitude) {
      step = m * magnitude;
      break;
    }
  }
  const double first = std::ceil(lo / step - 1e-9);
  const double last = std::floor(hi / step + 1e-9);
  for (double k = first; k <= last && ticks.at.size() < 50; k += 1.0) {
    double value = k * step;
    if (std::fabs(value) < step * 1e-9) value = 0.0;
    ticks.at.push_back(value);
    ticks.labels.push_back(number(value, 6));
  }
  return ticks;
}

double Area::px(double x) const {
  if (x_max == x_min) return left + width / 2;
  return left + (x - x_min) / (x_max - x_min) * width;
}

double Area::py(double y) const {
  if (y_max == y_min) return top + height / 2;
  return top + (y_max - y) / (y_max - y_min) * height;
}

void open(std::string& out, std::string_view name, std::string_view title, double width, double height) {
  out += "<svg xmlns=\"http://www.w3.org/2000/svg\" class=\"plot\" data-plot=\"";
  out += escape(name);
  out += "\" width=\"" + coord(width) + "\" height=\"" + coord(height) + "\" viewBox=\"0 0 " + coord(width) + " " +
         coord(height) + "\" role=\"img\" " + kFont + ">\n<title>";
  out += escape(title);
  out += "</title>\n";
  // A white background keeps the plot readable when copied out of the page.
  out += "<rect x=\"0\" y=\"0\" width=\"" + coord(width) + "\" height=\"" + coord(height) + "\" fill=\"#ffffff\"/>\n";
}

void close(std::string& out) { out += "</svg>\n"; }

void text(std::string& out, double x, double y, std::string_view content, std::string_view attributes) {
  out += "<text x=\"" + coord(x) + "\" y=\"" + coord(y) + "\"";
  if (!attributes.empty()) {
    out += ' ';
    out += attributes;
  }
  out += '>';
  out += escape(content);
  out += "</text>\n";
}

void axes(std::string& out, const Area& area, const Ticks& x_ticks, const Ticks& y_ticks, std::string_view x_label,
          std::string_view y_label) {
  const double bottom = area.top + area.height;
  const double right = area.left + area.width;
  out += "<rect x=\"" + coord(area.left) + "\" y=\"" + coord(area.top) + "\" width=\"" + coord(area.width) +
         "\" height=\"" + coord(area.height) + "\" fill=\"none\" stroke=\"" + kAxisColour + "\" stroke-width=\"1\"/>\n";
  const double x_lo = std::min(area.x_min, area.x_max);
  const double x_hi = std::max(area.x_min, area.x_max);
  const double y_lo = std::min(area.y_min, area.y_max);
  const double y_hi = std::max(area.y_min, area.y_max);
  const double x_slack = (x_hi - x_lo) * 1e-9;
  const double y_slack = (y_hi - y_lo) * 1e-9;
  std::string marks;
  for (std::size_t i = 0; i < x_ticks.at.size() && i < x_ticks.labels.size(); ++i) {
    const double v = x_ticks.at[i];
    if (!(v >= x_lo - x_slack && v <= x_hi + x_slack)) continue;
    const double x = area.px(v);
    marks += "M" + coord(x) + " " + coord(bottom) + "v4";
    text(out, x, bottom + 15, x_ticks.labels[i], "text-anchor=\"middle\"");
  }
  for (std::size_t i = 0; i < y_ticks.at.size() && i < y_ticks.labels.size(); ++i) {
    const double v = y_ticks.at[i];
    if (!(v >= y_lo - y_slack && v <= y_hi + y_slack)) continue;
    const double y = area.py(v);
    marks += "M" + coord(area.left) + " " + coord(y) + "h-4";
    text(out, area.left - 6, y + 4, y_ticks.labels[i], "text-anchor=\"end\"");
  }
  if (!marks.empty()) {
    out += "<path d=\"" + marks + "\" stroke=\"" + kAxisColour + "\" stroke-width=\"1\"/>\n";
  }
  text(out, (area.left + right) / 2, bottom + 32, x_label, "text-anchor=\"middle\"");
  const double yx = area.left - 44;
  const double yy = area.top + area.height / 2;
  text(out, yx, yy, y_label, "text-anchor=\"middle\" transform=\"rotate(-90 " + coord(yx) + " " + coord(yy) + ")\"");
}

void polyline(std::string& out, const Area& area, const std::vector<double>& xs, const std::vector<double>& ys,
              std::string_view attributes) {
  const std::size_t n = std::min(xs.size(), ys.size());
  std::string points;
  std::size_t count = 0;
  const auto flush = [&] {
    if (count == 1) points += " " + points;  // a lone point: a zero-length segment, drawn as a dot
    if (count > 0) {
      out += "<polyline fill=\"none\" stroke-linecap=\"round\" stroke-linejoin=\"round\" ";
      out += attributes;
      out += " points=\"" + points + "\"/>\n";
    }
    points.clear();
    count = 0;
  };
  for (std::size_t i = 0; i < n; ++i) {
    const double x = area.px(xs[i]);
    const double y = area.py(ys[i]);
    if (!std::isfinite(x) || !std::isfinite(y)) {
      flush();
      continue;
    }
    if (count > 0) points += ' ';
    points += coord(x) + "," + coord(y);
    ++count;
  }
  flush();
}

void colour_bar(std::string& out, double left, double top, double width, double height, double v_min, double v_max,
                int levels, std::string_view label, bool clamped_top) {
  levels = std::max(levels, 1);
  const double band = height / static_cast<double>(levels);
  for (int i = 0; i < levels; ++i) {
    const double t = (static_cast<double>(i) + 0.5) / static_cast<double>(levels);
    // Band 0 (lowest values) sits at the bottom. Bands overlap by a hair to avoid seams.
    const double y = top + height - static_cast<double>(i + 1) * band;
    out += "<rect x=\"" + coord(left) + "\" y=\"" + coord(y) + "\" width=\"" + coord(width) + "\" height=\"" +
           coord(band + 0.5) + "\" fill=\"" + colour(t) + "\"/>\n";
  }
  Area area;
  area.left = left;
  area.top = top;
  area.width = width;
  area.height = height;
  area.y_min = v_min;
  area.y_max = v_max;
  out += "<rect x=\"" + coord(left) + "\" y=\"" + coord(top) + "\" width=\"" + coord(width) + "\" height=\"" +
         coord(height) + "\" fill=\"none\" stroke=\"" + kAxisColour + "\"/>\n";
  const Ticks ticks = linear_ticks(v_min, v_max, 5);
  std::string marks;
  for (std::size_t i = 0; i < ticks.at.size(); ++i) {
    const double y = area.py(ticks.at[i]);
    marks += "M" + coord(left + width) + " " + coord(y) + "h4";
    text(out, left + width + 6, y + 4, ticks.labels[i]);
  }
  if (!marks.empty()) {
    out += "<path d=\"" + marks + "\" stroke=\"" + kAxisColour + "\" stroke-width=\"1\"/>\n";
  }
  if (clamped_top) {
    text(out, left + width / 2, top - 6, "\u2265 " + number(v_max, 3), "text-anchor=\"middle\"");
  }
  const double lx = left + width + 52;
  const double ly = top + height / 2;
  text(out, lx, ly, label, "text-anchor=\"middle\" transform=\"rotate(-90 " + coord(lx) + " " + coord(ly) + ")\"");
}

}  // namespace pliant::host::svg
