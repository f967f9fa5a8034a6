// Progress of `pliant refine` on stderr: one status line naming the stage (which estimator, which
// fit), the optimiser's pass, iteration and cost, and the elapsed time.
//
// Unlike ProgressBar (progress_bar.hpp) the total is not known in advance (a fit ends when it
// converges), and some stages report nothing while they run (the modal warm start, the rest
// shape, the final simulation), so a background thread redraws the line every 250 ms with the
// elapsed time. Drawn only when stderr is a terminal and `enabled` (no --quiet), not at all for
// work that finishes within half a second, and erased when done so the summary or an error
// message starts on a clean line. stage() and iteration() may be called from any thread.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <mutex>
#include <string>
#include <thread>

namespace pliant::cli {

class RefineProgress {
 public:
  explicit RefineProgress(bool enabled);
  ~RefineProgress();
  RefineProgress(const RefineProgress&) = delete;
  RefineProgress& operator=(const RefineProgress&) = delete;

  /// A new stage ("youngs_modulus: reaction fit"); clears the iteration detail.
  void stage(const std::string& text);
  /// For FitOptions::on_iteration: pass, iteration and cost of the current fit.
  void iteration(int pass, int iteration, double cost);
  /// Stops redrawing and erases the line (also done by the destructor).
  void finish();

 private:
  void run();
  void draw_locked();

  bool active_ = false;
  std::mutex mutex_;
  std::condition_variable wake_;
  bool stopping_ = false;
  std::string stage_;
  std::string detail_;
  std::size_t drawn_width_ = 0;
  std::chrono::steady_clock::time_point start_;
  std::thread thread_;
};

}  // namespace pliant::cli
