#include "job_simulate.hpp"

#include <cstdio>
#include <stdexcept>

#include "exit_status.hpp"
#include "output_directory.hpp"

namespace pliant::cli {
namespace {

// Bounds the frame count (and memory) of a scenario a few seconds long.
constexpr double max_rate_hz = 10000.0;

std::string number(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%g", value);
  return buffer;
}

// The scenario options the job's optional values complete; the library reads rate 0 and depth 0
// as "the scenario's own", which on the command line is leaving the option out.
host::ScenarioOptions scenario_options(const SimulateJob& job) {
  host::ScenarioOptions options = job.options;
  if (job.rate) {
    if (!(*job.rate > 0.0)) throw UsageError("--rate must be > 0");
    if (*job.rate > max_rate_hz) throw UsageError("--rate must be at most " + number(max_rate_hz));
    options.rate_hz = *job.rate;
  }
  if (job.depth) {
    if (!(*job.depth > 0.0)) throw UsageError("--depth must be in (0, 2]");
    options.depth = *job.depth;
  }
  return options;
}

}  // namespace

host::ScenarioResult run_simulate_job(const SimulateJob& job) {
  host::ScenarioOptions options = scenario_options(job);
  if (job.output) check_output_directory(*job.output, job.force);
  host::ScenarioResult scenario;
  try {
    if (job.effect) host::parse_effect_argument(*job.effect, options);
    scenario = host::make_scenario(job.scenario, options);
  } catch (const std::invalid_argument& e) {
    // make_scenario validates the scenario name, the option values and the effect.
    throw UsageError(e.what());
  }
  if (job.output) host::write_scenario(scenario, *job.output);
  return scenario;
}

std::string simulate_summary(const SimulateJob& job, const host::ScenarioResult& scenario) {
  const host::Recording& rec = scenario.recording;
  // The summary names what is visible in the recording; the effect stays in truth.json.
  return "wrote " + job.output.value_or("") + ": " + job.scenario + ", " + std::to_string(rec.particle_count) +
         " particles x " + std::to_string(rec.frame_count()) + " frames (" + std::to_string(rec.dimension) + "D, " +
         rec.length_unit + "), msm_beta " + number(job.options.msm_beta) + ", msm_alpha " +
         number(job.options.msm_alpha) + ", noise " + number(job.options.noise) + ", seed " +
         std::to_string(job.options.seed) + "; truth in truth.json\n";
}

}  // namespace pliant::cli
