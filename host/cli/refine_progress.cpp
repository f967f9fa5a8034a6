#include "refine_progress.hpp"

#include <sys/ioctl.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>

namespace pliant::cli {
namespace {

constexpr auto redraw_interval = std::chrono::milliseconds(250);
constexpr auto first_draw_after = std::chrono::milliseconds(500);

// A line longer than the terminal wraps, and '\r' then cannot erase it.
std::size_t terminal_columns() {
  winsize size{};
  if (ioctl(STDERR_FILENO, TIOCGWINSZ, &size) == 0 && size.ws_col > 1) return static_cast<std::size_t>(size.ws_col) - 1;
  return 79;
}

}  // namespace

RefineProgress::RefineProgress(bool enabled)
    : active_(enabled && isatty(STDERR_FILENO) == 1), start_(std::chrono::steady_clock::now()) {
  if (active_) thread_ = std::thread([this] { run(); });
}

RefineProgress::~RefineProgress() { finish(); }

void RefineProgress::stage(const std::string& text) {
  const std::lock_guard<std::mutex> lock(mutex_);
  stage_ = text;
  detail_.clear();
}

void RefineProgress::iteration(int pass, int iteration, double cost) {
  char text[96];
  std::snprintf(text, sizeof text, "pass %d, iteration %d, cost %.4g", pass + 1, iteration, cost);
  const std::lock_guard<std::mutex> lock(mutex_);
  detail_ = text;
}

void RefineProgress::finish() {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (stopping_) return;
    stopping_ = true;
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
  const std::lock_guard<std::mutex> lock(mutex_);
  if (drawn_width_ > 0) {
    std::fprintf(stderr, "\r%s\r", std::string(drawn_width_, ' ').c_str());
    std::fflush(stderr);
    drawn_width_ = 0;
  }
}

void RefineProgress::run() {
  std::unique_lock<std::mutex> lock(mutex_);
  if (wake_.wait_until(lock, start_ + first_draw_after, [this] { return stopping_; })) return;
  while (!stopping_) {
    draw_locked();
    wake_.wait_for(lock, redraw_interval, [this] { return stopping_; });
  }
}

void RefineProgress::draw_locked() {
  const auto elapsed = std::chrono::duration_cast<std::chrono::seconds>(std::chrono::steady_clock::now() - start_);
  // Time first: a narrow terminal cuts the end of the line.
  std::string line = "refine [" + std::to_string(elapsed.count()) + " s] " + stage_;
  if (!detail_.empty()) line += ": " + detail_;
  const std::size_t columns = terminal_columns();
  if (line.size() > columns) line.resize(columns);
  // Pad over the previous drawing, which may have been longer.
  const std::size_t width = line.size();
  if (width < drawn_width_) line.append(drawn_width_ - width, ' ');
  std::fprintf(stderr, "\r%s", line.c_str());
  std::fflush(stderr);
  drawn_width_ = std::max(width, drawn_width_);
}

}  // namespace pliant::cli
