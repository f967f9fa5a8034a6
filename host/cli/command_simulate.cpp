#include "command_simulate.hpp"

#include <iostream>
#include <string>
#include <vector>

#include "exit_status.hpp"
#include "job_simulate.hpp"

namespace pliant::cli {
namespace {

std::string joined(const std::vector<std::string>& names) {
  std::string text;
  for (const std::string& name : names) text += (text.empty() ? "" : ", ") + name;
  return text;
}

}  // namespace

SimulateCommand::SimulateCommand(CLI::App& parent) {
  app_ = parent.add_subcommand("simulate", "Write a simulated recording with known msm_beta (and its truth.json)");
  app_->footer("Scenarios: " + joined(host::scenario_names()) +
               ".\nEffects for --effect, with their defaults: " + host::describe_effects() +
               ".\nThe recording never mentions the effect, the substeps, the cluster radius or the occlusion; "
               "truth.json holds them with the true parameters, for checking. No estimator reads it.");
  app_->add_option("SCENARIO", scenario_, "One of: " + joined(host::scenario_names()))->required();
  app_->add_option("-o,--output", output_, "Recording directory to write (created if missing)")
      ->type_name("DIR")
      ->required();
  app_->add_option("--beta", options_.msm_beta, "True msm_beta, in [0, 1]")->type_name("B")->capture_default_str();
  app_->add_option("--alpha", options_.msm_alpha, "True msm_alpha, in (0, 1]")->type_name("A")->capture_default_str();
  app_->add_option("--noise", options_.noise,
                   "Position noise std as a fraction of the particle spacing (0.005 = 0.5 %)")
      ->type_name("F")
      ->capture_default_str();
  // CLI11 would wrap a negative value into a huge unsigned seed.
  app_->add_option("--seed", options_.seed, "Noise seed (>= 0)")
      ->type_name("S")
      ->check(CLI::Validator(
          [](std::string& value) { return value.rfind('-', 0) == 0 ? std::string("must be >= 0") : std::string(); }, "",
          "non-negative"))
      ->capture_default_str();
  app_->add_option("--rate", options_.rate_hz, "Frames per second (default: the scenario's own rate)")->type_name("HZ");
  // Parsed in run(), where a bad name becomes a usage error naming the valid ones.
  app_->add_option("--effect", options_.effect,
                   "Concealed effect switched on in the simulation, with optional parameters, e.g. "
                   "plasticity:yield=0.02,creep=4 or heterogeneity:ratio=0.3,region=left")
      ->type_name("NAME[:P=V,...]");
  app_->add_option("--substeps", options_.substeps, "MSM steps per frame interval, 1..64 (estimators fit 1)")
      ->type_name("N")
      ->capture_default_str();
  app_->add_option("--cluster-radius", options_.cluster_radius_factor,
                   "Generator's cluster radius / median neighbour distance, in [1, 4] (estimators use 1.5)")
      ->type_name("F")
      ->capture_default_str();
  app_->add_option("--occlusion", options_.occlusion,
                   "Share of (particle, frame) observations removed in runs of frames, in [0, 0.5]; never frame 0 "
                   "nor the driven particle while driven")
      ->type_name("F")
      ->capture_default_str();
  app_->add_option("--depth", options_.depth,
                   "Tool travel as a fraction of the object's height, in (0, 2] (default: the scenario's own)")
      ->type_name("F");
  app_->add_flag("--release", options_.release,
                 "foam_press, block_press: the tool lets go after the hold and 1.5 s more are recorded "
                 "(the other scenarios always release)");
  app_->add_flag("--force", force_, "Write into a non-empty DIR, replacing files of the same names");
}

int SimulateCommand::run() const {
  SimulateJob job;
  job.scenario = scenario_;
  job.output = output_;
  job.options = options_;
  if (app_->count("--rate") > 0) job.rate = options_.rate_hz;
  if (app_->count("--depth") > 0) job.depth = options_.depth;
  if (app_->count("--effect") > 0) job.effect = options_.effect;
  job.force = force_;
  const host::ScenarioResult scenario = run_simulate_job(job);
  std::cout << simulate_summary(job, scenario);
  return exit_ok;
}

}  // namespace pliant::cli
