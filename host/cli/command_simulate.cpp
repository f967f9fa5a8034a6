#include "command_simulate.hpp"

#include <cstdio>
#include <filesystem>
#include <iostream>
#include <stdexcept>
#include <string>
#include <system_error>
#include <vector>

#include "exit_status.hpp"

namespace pliant::cli {
namespace {

namespace fs = std::filesystem;

// Bounds the frame count (and memory) of a scenario a few seconds long.
constexpr double max_rate_hz = 10000.0;

std::string joined(const std::vector<std::string>& names) {
  std::string text;
  for (const std::string& name : names) text += (text.empty() ? "" : ", ") + name;
  return text;
}

void check_output_directory(const std::string& directory, bool force) {
  std::error_code error;
  const fs::file_status status = fs::status(directory, error);
  if (!fs::exists(status)) return;
  if (!fs::is_directory(status)) throw UsageError(directory + " exists and is not a directory");
  if (force) return;
  const bool empty = fs::is_empty(directory, error);
  if (error) throw std::runtime_error("cannot read " + directory + ": " + error.message());
  if (!empty) throw UsageError(directory + " is not empty; pass --force to replace the recording in it");
}

std::string number(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%g", value);
  return buffer;
}

}  // namespace

SimulateCommand::SimulateCommand(CLI::App& parent) {
  app_ = parent.add_subcommand("simulate", "Write a simulated recording with known msm_beta (and its truth.json)");
  app_->footer("Scenarios: " + joined(host::scenario_names()) +
               ". truth.json holds the true parameters for checking; no estimator reads it.");
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
          [](std::string& value) { return value.rfind('-', 0) == 0 ? std::string("must be >= 0") : std::string(); },
          "", "non-negative"))
      ->capture_default_str();
  app_->add_option("--rate", options_.rate_hz, "Frames per second (default: the scenario's own rate)")
      ->type_name("HZ");
  app_->add_flag("--force", force_, "Write into a non-empty DIR, replacing files of the same names");
}

int SimulateCommand::run() const {
  // The library reads rate 0 as "the scenario's own rate"; on the command line that is leaving it out.
  if (app_->count("--rate") > 0 && !(options_.rate_hz > 0.0)) throw UsageError("--rate must be > 0");
  if (options_.rate_hz > max_rate_hz) throw UsageError("--rate must be at most " + number(max_rate_hz));
  check_output_directory(output_, force_);
  host::ScenarioResult scenario;
  try {
    scenario = host::make_scenario(scenario_, options_);
  } catch (const std::invalid_argument& e) {
    // make_scenario validates the scenario name and the option values.
    throw UsageError(e.what());
  }
  host::write_scenario(scenario, output_);

  const host::Recording& rec = scenario.recording;
  std::cout << "wrote " << output_ << ": " << scenario_ << ", " << rec.particle_count << " particles x "
            << rec.frame_count() << " frames (" << rec.dimension << "D, " << rec.length_unit
            << "), msm_beta " << number(options_.msm_beta) << ", msm_alpha " << number(options_.msm_alpha)
            << ", noise " << number(options_.noise) << ", seed " << options_.seed << "; truth in truth.json\n";
  return exit_ok;
}

}  // namespace pliant::cli
