#include "command_estimate.hpp"

#include <iostream>
#include <stdexcept>

#include "atomic_write.hpp"
#include "estimate_summary.hpp"
#include "exit_status.hpp"
#include "model_form_options.hpp"
#include "progress_bar.hpp"
#include "pliant/host/estimate.hpp"
#include "pliant/host/recording.hpp"

namespace pliant::cli {
namespace {

// Far above any useful resolution; bounds the curve the estimator has to hold.
constexpr int max_grid_points = 1001;

}  // namespace

EstimateCommand::EstimateCommand(CLI::App& parent) {
  app_ = parent.add_subcommand("estimate", "Estimate msm_beta (MSM deformability) of a recording");
  app_->footer(
      "Prints a summary with the error curve. Exit status: 0 ok, 1 estimation failed, 2 bad options "
      "or a malformed recording.");
  app_->add_option("REC", recording_, "Recording directory (docs/spec/recording-v1.md)")->required();
  app_->add_option("--json", json_path_,
                   "Also write the pliant-estimate v1 JSON to OUT (atomically); '-' prints it to stdout "
                   "instead of the summary")
      ->type_name("OUT");
  app_->add_option("--mode", mode_, "'trajectory': simulate every frame; 'final': match the final equilibrium only")
      ->type_name("final|trajectory")
      ->capture_default_str();
  model_form_.add_to(*app_);
  app_->add_option("--grid", grid_points_, "Grid points over msm_beta in [0, 1] before refinement (>= 3)")
      ->type_name("N")
      ->capture_default_str();
  app_->add_flag("-q,--quiet", quiet_, "No progress bar");
}

int EstimateCommand::run() const {
  host::EstimateOptions options;
  try {
    options.mode = host::parse_fit_mode(mode_);
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
  const ModelFormChoice form = model_form_.apply(*app_);
  options.alpha = form.alpha;
  options.msm_alpha = form.msm_alpha;
  options.steps_per_frame = form.steps_per_frame;
  options.cluster_radius_auto = form.cluster_radius_auto;
  options.setup.clusters.radius_factor = form.cluster_radius_factor;
  if (options.alpha == host::AlphaMode::fitted && options.mode != FitMode::trajectory) {
    throw UsageError("--alpha fit needs --mode trajectory");
  }
  if (grid_points_ < 3 || grid_points_ > max_grid_points) {
    throw UsageError("--grid must be between 3 and " + std::to_string(max_grid_points));
  }
  options.grid_points = grid_points_;

  const host::Recording recording = host::read_recording(recording_);
  for (const std::string& warning : recording.warnings) report_warning(warning);

  host::EstimateReport report;
  {
    ProgressBar bar("estimating msm_beta", !quiet_);
    options.progress = &ProgressBar::callback;
    options.progress_context = &bar;
    report = host::estimate_recording(recording, options);
    options.progress = nullptr;
    options.progress_context = nullptr;
  }

  const nlohmann::json document = host::estimate_json(recording, options, report);
  if (json_path_ == "-") {
    std::cout << document.dump(2) << '\n';
    for (const std::string& warning : estimate_warnings(report)) report_warning(warning);
  } else {
    if (!json_path_.empty()) write_file_atomically(json_path_, document.dump(2) + "\n");
    std::cout << format_estimate_summary(recording, options, report);
    if (!json_path_.empty()) std::cout << "\nwrote " << json_path_ << '\n';
  }
  std::cout.flush();
  if (!std::cout) throw std::runtime_error("cannot write to standard output");
  return exit_ok;
}

}  // namespace pliant::cli
