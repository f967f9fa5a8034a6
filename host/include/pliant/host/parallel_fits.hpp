// Independent fits on worker threads: the candidate effects of the MSM and FEM diagnoses and
// the variants of the estimate's baseline selection.
//
// run_on_workers(count, workers, make_state, fit, done): fit(state, index) for every index in
// [0, count), spread over `workers` threads (at least one: the caller's). Each thread first
// makes its own state with make_state(is_caller) (a simulator holds its run state, so every
// thread needs its own); the indices are taken in order from a shared counter. After each fit,
// done() is called under a lock (progress reporting). The first exception stops new fits and is
// rethrown in the caller once every thread has joined. The results are whatever fit() writes:
// a fit must depend on its index only, so that nothing depends on the thread count. Host code.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <exception>
#include <mutex>
#include <system_error>
#include <thread>
#include <vector>

namespace pliant::host {

/// Worker threads for `count` independent fits: `requested` when positive, else one per
/// hardware thread; never more than the fits.
inline std::size_t worker_count(std::size_t count, int requested) {
  const unsigned hardware = std::max(1u, std::thread::hardware_concurrency());
  return std::max<std::size_t>(
      1, std::min<std::size_t>(count, requested > 0 ? static_cast<std::size_t>(requested) : hardware));
}

template <typename MakeState, typename Fit, typename Done>
void run_on_workers(std::size_t count, std::size_t workers, MakeState&& make_state, Fit&& fit, Done&& done) {
  std::atomic<std::size_t> next{0};
  std::mutex mutex;  // guards failure and done()
  std::exception_ptr failure;
  auto work = [&](bool is_caller) {
    try {
      auto state = make_state(is_caller);
      for (std::size_t index = next++; index < count; index = next++) {
        fit(state, index);
        const std::lock_guard<std::mutex> lock(mutex);
        done();
      }
    } catch (...) {
      const std::lock_guard<std::mutex> lock(mutex);
      if (!failure) failure = std::current_exception();
      next = count;
    }
  };
  std::vector<std::thread> threads;
  for (std::size_t w = 1; w < workers; ++w) {
    try {
      threads.emplace_back(work, false);
    } catch (const std::system_error&) {
      break;  // no more threads to be had: the workers already started share the fits
    }
  }
  work(true);
  for (std::thread& thread : threads) thread.join();
  if (failure) std::rethrow_exception(failure);
}

}  // namespace pliant::host
