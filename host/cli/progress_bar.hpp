// A one-line progress bar on stderr for long estimations.
//
// Drawn only when stderr is a terminal, so logs and pipes stay clean; redrawn at most every
// 100 ms and not at all for work that finishes sooner; erased when done so the summary or an
// error message starts on a clean line.
#pragma once

#include <chrono>
#include <cstddef>
#include <string>

namespace pliant::cli {

class ProgressBar {
 public:
  /// `enabled` false (e.g. --quiet) suppresses the bar even on a terminal.
  ProgressBar(std::string label, bool enabled);
  ~ProgressBar();
  ProgressBar(const ProgressBar&) = delete;
  ProgressBar& operator=(const ProgressBar&) = delete;

  void update(int done, int total);
  /// Erases the bar; later updates draw it again.
  void clear();

  /// Adapter for pliant::ProgressCallback; `bar` is a ProgressBar*.
  static void callback(void* bar, int done, int total);

 private:
  std::string label_;
  bool active_ = false;
  std::size_t drawn_width_ = 0;  // characters on screen, 0 when nothing is drawn
  std::chrono::steady_clock::time_point last_draw_;
};

}  // namespace pliant::cli
