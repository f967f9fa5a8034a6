#include "progress_bar.hpp"

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <utility>

namespace pliant::cli {
namespace {

constexpr auto redraw_interval = std::chrono::milliseconds(100);
constexpr int bar_cells = 30;

}  // namespace

ProgressBar::ProgressBar(std::string label, bool enabled)
    : label_(std::move(label)),
      active_(enabled && isatty(STDERR_FILENO) == 1),
      last_draw_(std::chrono::steady_clock::now()) {}

ProgressBar::~ProgressBar() { clear(); }

void ProgressBar::update(int done, int total) {
  if (!active_ || total <= 0) return;
  const auto now = std::chrono::steady_clock::now();
  if (now - last_draw_ < redraw_interval) return;
  last_draw_ = now;

  const int shown = std::clamp(done, 0, total);
  const int filled = shown * bar_cells / total;
  std::string line = label_ + " [";
  line.append(static_cast<std::size_t>(filled), '#');
  line.append(static_cast<std::size_t>(bar_cells - filled), '.');
  line += "] " + std::to_string(shown) + "/" + std::to_string(total);
  // Pad over the previous drawing: the total may grow, the text may shrink.
  const std::size_t width = line.size();
  if (width < drawn_width_) line.append(drawn_width_ - width, ' ');
  std::fprintf(stderr, "\r%s", line.c_str());
  std::fflush(stderr);
  drawn_width_ = std::max(width, drawn_width_);
}

void ProgressBar::clear() {
  if (drawn_width_ == 0) return;
  std::fprintf(stderr, "\r%s\r", std::string(drawn_width_, ' ').c_str());
  std::fflush(stderr);
  drawn_width_ = 0;
}

void ProgressBar::callback(void* bar, int done, int total) { static_cast<ProgressBar*>(bar)->update(done, total); }

}  // namespace pliant::cli
