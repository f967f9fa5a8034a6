// estimate_call_bench: the C++ side of bench/python_estimate_overhead.py. Times the job behind
// `pliant estimate` (host/cli/job_estimate.hpp, run_estimate_job with the default options) on a
// recording already in memory, as pliant.estimate(recording) runs it from Python: the recording
// copied into the job, the estimate, the pliant-estimate document.
//
// Usage: estimate_call_bench RECORDING [--calls N]   (default 5)
// Prints one line per call and, last, one JSON object: {"calls", "min_s", "median_s"} (wall time
// of one call).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "job_estimate.hpp"

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: estimate_call_bench RECORDING [--calls N]\n");
    return 2;
  }
  int calls = 5;
  for (int i = 2; i + 1 < argc; ++i) {
    if (std::string(argv[i]) == "--calls") calls = std::max(1, std::atoi(argv[i + 1]));
  }
  std::printf("estimate_call_bench (%s build)\n", PLIANT_BENCH_BUILD_TYPE);
  const pliant::host::Recording recording = pliant::host::read_recording(argv[1]);
  const pliant::cli::RecordingSource source = [&recording] { return recording; };
  const pliant::cli::WarningSink ignore = [](const std::string&) {};
  pliant::cli::EstimateJob job;  // the defaults of `pliant estimate REC` (quiet)
  std::vector<double> seconds;
  double beta = 0;
  for (int call = 0; call < calls; ++call) {
    const auto start = std::chrono::steady_clock::now();
    const pliant::cli::EstimateDone done = pliant::cli::run_estimate_job(job, source, ignore);
    seconds.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    beta = done.report.result.msm_beta;
    std::printf("call %d: %.6f s, msm_beta %.4f\n", call + 1, seconds.back(), beta);
  }
  std::sort(seconds.begin(), seconds.end());
  std::printf("{\"calls\": %d, \"min_s\": %.9f, \"median_s\": %.9f, \"msm_beta\": %.6f}\n", calls, seconds.front(),
              seconds[seconds.size() / 2], beta);
  return 0;
}
