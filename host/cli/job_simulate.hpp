// The job of `pliant simulate`: a simulated recording with known ground truth (job.hpp).
#pragma once

#include <optional>
#include <string>

#include "pliant/host/scenarios.hpp"

namespace pliant::cli {

/// The options of `pliant simulate`, by their long names. Options a scenario reads as "its own
/// value" when zero (rate, depth) are empty optionals when not given.
struct SimulateJob {
  std::string scenario;               ///< SCENARIO, one of host::scenario_names()
  std::optional<std::string> output;  ///< -o DIR; empty: nothing written (the Python module's in-memory run)
  /// --beta, --alpha, --noise, --seed, --substeps, --cluster-radius, --occlusion, --release
  host::ScenarioOptions options;
  std::optional<double> rate;         ///< --rate HZ, > 0 and at most 10 kHz
  std::optional<double> depth;        ///< --depth F, in (0, 2]
  std::optional<std::string> effect;  ///< --effect NAME[:P=V,...]
  bool force = false;                 ///< --force: write into a non-empty DIR
};

/// Checks the options, simulates, and writes the recording and truth.json into job.output.
/// Throws UsageError with the command line's message for bad options, a bad scenario or effect,
/// or an output directory that is not empty (without force); std::runtime_error on I/O failure.
host::ScenarioResult run_simulate_job(const SimulateJob& job);

/// The command's one line: what was written, with the visible parameters (not the effect).
std::string simulate_summary(const SimulateJob& job, const host::ScenarioResult& scenario);

}  // namespace pliant::cli
