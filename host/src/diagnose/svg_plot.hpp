// Small inline-SVG drawing kit for the diagnosis report: text escaping, number formatting, a
// perceptual colour map, tick placement, axes and polylines. Output is appended to a string.
// Everything uses presentation attributes (no CSS classes), so a plot also renders when it is
// cut out of the page on its own. Not installed.
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace pliant::host::svg {

/// `text` escaped for HTML/SVG text and attribute values (& < > " '). Control bytes other than
/// tab and newline become '?', so nothing in the input can open markup or break the page.
std::string escape(std::string_view text);

/// Human-readable number with `digits` significant digits; "n/a" for NaN, "inf"/"-inf".
std::string number(double value, int digits = 3);

/// Pixel coordinate with at most two decimals and no trailing zeros ("12.5", "3").
std::string coord(double value);

/// Colour of `t` in [0, 1] on a viridis-like ramp (dark violet -> yellow), as "#rrggbb".
/// `t` is clamped; NaN gives the neutral grey used for missing data.
std::string colour(double t);

/// Grey used for cells without data.
inline constexpr const char* kMissingGrey = "#d9d9d9";

/// Tick positions (in data units) and their labels for one axis.
struct Ticks {
  std::vector<double> at;
  std::vector<std::string> labels;
};

/// About `target` round-numbered ticks (1, 2, 5 x 10^k steps) inside [lo, hi].
Ticks linear_ticks(double lo, double hi, int target = 5);

/// A rectangle on the canvas (pixels) and the data range it shows. y grows upwards in data
/// units unless y_min > y_max, which flips the axis (used for "row 0 at the top").
struct Area {
  double left = 0, top = 0, width = 1, height = 1;
  double x_min = 0, x_max = 1, y_min = 0, y_max = 1;
  double px(double x) const;
  double py(double y) const;
};

/// Opens `<svg class="plot" data-plot="name">` of the given size with a `<title>` and closes it.
void open(std::string& out, std::string_view name, std::string_view title, double width, double height);
void close(std::string& out);

/// Text at (x, y) in pixels; `attributes` is inserted verbatim (e.g. text-anchor="end").
void text(std::string& out, double x, double y, std::string_view content, std::string_view attributes = "");

/// Frame, ticks with labels, and axis titles around `area`. Ticks outside the data range are
/// dropped.
void axes(std::string& out, const Area& area, const Ticks& x_ticks, const Ticks& y_ticks, std::string_view x_label,
          std::string_view y_label);

/// The points (xs[i], ys[i]) joined in order; NaN in either coordinate breaks the line into
/// separate pieces. `attributes` styles the line (stroke, stroke-width, dasharray...).
void polyline(std::string& out, const Area& area, const std::vector<double>& xs, const std::vector<double>& ys,
              std::string_view attributes);

/// Vertical colour bar for the range [v_min, v_max] drawn with `levels` bands, labelled with
/// ticks and `label`; `clamped_top` marks the top value as "at least".
void colour_bar(std::string& out, double left, double top, double width, double height, double v_min, double v_max,
                int levels, std::string_view label, bool clamped_top);

}  // namespace pliant::host::svg
